//! Checked specs to Rust: a module per spec with its state type, options enums, monitors
//! and an implementation of the runtime's `Spec` trait.

use std::collections::HashSet;

use hstl_lang::{
    Bound, CExpr, CExprKind, CFormula, CFormulaKind, CheckedSpec, CmpOp, Domain, Interval,
    Terminate, VarType,
};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

/// The generated module of one spec. `complete` says whether the spec checked without
/// errors; otherwise only the parts that checked are generated (no `Spec` implementation),
/// so an editor keeps completing inside a half-typed spec.
pub fn spec_module(
    spec: &CheckedSpec,
    src: &str,
    complete: bool,
    root: &TokenStream,
) -> TokenStream {
    let g = Gen::new(spec, root.clone());
    let module = ident(&snake_case(&spec.name));
    let doc = doc_attrs(spec.doc.as_deref());
    let state = g.state();
    let primitives = g.primitive_enum();
    let options = g.options_enum();
    let lets = g.lets();
    let task = match &spec.task {
        Some(t) if g.valid(&t.formula) => g.monitor(
            &t.formula,
            None,
            &quote!(super::lets),
            &quote!(super::State),
            &doc_or(t.doc.as_deref(), "The task: its robustness monitors."),
            &quote!(task),
        ),
        _ => TokenStream::new(),
    };
    let spec_impl = if complete { g.spec_impl(src) } else { TokenStream::new() };
    let world = match &spec.world {
        Some(w) => {
            let name = &w.name;
            quote!(::core::option::Option::Some(#name))
        }
        None => quote!(::core::option::Option::None),
    };
    quote! {
        #doc
        #[allow(dead_code)]
        pub mod #module {
            /// The world the spec names with `world "...";` (a built-in world's name, or a
            /// world file's path relative to the spec), if any: the macro reads no file, so
            /// the spec is checked alone.
            pub const WORLD: ::core::option::Option<&'static str> = #world;
            #state
            #primitives
            #options
            #task
            /// The monitors of the spec's `let`s, one module each.
            pub mod lets {
                #lets
            }
            #spec_impl
        }
    }
}

/// The module name of a spec.
pub fn module_name(spec: &CheckedSpec) -> String {
    snake_case(&spec.name)
}

struct Gen<'a> {
    spec: &'a CheckedSpec,
    // Rust names of the lets (snake case, made unique), by let index.
    let_names: Vec<Ident>,
    // Variant names of the primitive and combined options.
    prim_variants: Vec<Ident>,
    option_variants: Vec<Ident>,
    // The path generated code names the facade by: `$crate` through `hstl::hstl!`, or
    // `::hstl` when the proc macro is called directly.
    root: TokenStream,
    // Per let, computed once in dependency order so that no analysis walks a chain of
    // lets (or a let used twice) more than once: whether it checked (with every let it
    // uses), its horizon, and its value on the empty trace.
    let_valid: Vec<bool>,
    let_horizon: Vec<Option<usize>>,
    let_empty: Vec<f64>,
    // Valid state lets that name no other let: their values are fused into each step's
    // expression through `__at_<i>` (no chain can grow from them), where other lets are
    // read from the signals `__signals` computed once.
    let_leaf: Vec<bool>,
}

impl<'a> Gen<'a> {
    fn new(spec: &'a CheckedSpec, root: TokenStream) -> Gen<'a> {
        let mut taken = HashSet::new();
        let let_names =
            spec.lets.iter().map(|l| unique(&mut taken, snake_case(&l.name), "let")).collect();
        let mut taken = HashSet::new();
        let prim_variants = spec
            .primitives
            .iter()
            .map(|p| unique(&mut taken, camel_case(&p.name), "Option"))
            .collect();
        let mut taken = HashSet::new();
        let option_variants = spec
            .options
            .iter()
            .map(|o| unique(&mut taken, camel_case(&o.name), "Option"))
            .collect();
        let n = spec.lets.len();
        let mut g = Gen {
            spec,
            let_names,
            prim_variants,
            option_variants,
            root,
            let_valid: vec![false; n],
            let_horizon: vec![None; n],
            let_empty: vec![f64::NAN; n],
            let_leaf: vec![false; n],
        };
        // `let_order` lists every let after the lets it uses (and leaves out cycles).
        for &i in &spec.let_order {
            let f = &spec.lets[i].formula;
            g.let_valid[i] = g.valid(f);
            g.let_horizon[i] = g.horizon(f);
            g.let_empty[i] = g.empty_value(f);
            g.let_leaf[i] = g.let_valid[i]
                && spec.lets[i].kind == hstl_lang::LetKind::State
                && let_deps(f).is_empty();
        }
        g
    }

    /// Whether a formula (and every let it uses) checked.
    fn valid(&self, f: &CFormula) -> bool {
        match &f.kind {
            CFormulaKind::Invalid => false,
            CFormulaKind::True | CFormulaKind::False => true,
            CFormulaKind::Let(i) => self.let_valid.get(*i).copied().unwrap_or(false),
            CFormulaKind::Cmp(_, a, b) => valid_expr(a) && valid_expr(b),
            CFormulaKind::Not(a) | CFormulaKind::Always(_, a) | CFormulaKind::Eventually(_, a) => {
                self.valid(a)
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                !v.is_empty() && v.iter().all(|g| self.valid(g))
            }
            CFormulaKind::Once(_, a)
            | CFormulaKind::Historically(_, a)
            | CFormulaKind::Prev(a)
            | CFormulaKind::Next(a) => self.valid(a),
            CFormulaKind::Implies(a, b)
            | CFormulaKind::Until(_, a, b)
            | CFormulaKind::Since(_, a, b) => self.valid(a) && self.valid(b),
        }
    }

    fn state(&self) -> TokenStream {
        let vars = &self.spec.state_vars;
        let n = vars.len();
        let fields: Vec<Ident> = vars.iter().map(|v| ident(&v.name)).collect();
        let names: Vec<&str> = vars.iter().map(|v| v.name.as_str()).collect();
        let decls = vars.iter().zip(&fields).map(|(v, f)| {
            let doc = doc_or(v.doc.as_deref(), &format!("The state variable `{}`.", v.name));
            let ty = rust_type(v.ty);
            quote! { #doc pub #f: #ty, }
        });
        let values = vars.iter().zip(&fields).map(|(v, f)| match v.ty {
            VarType::Int => quote!(self.#f as f64),
            VarType::Float | VarType::Time => quote!(self.#f),
        });
        let from = vars.iter().zip(&fields).enumerate().map(|(i, (v, f))| match v.ty {
            VarType::Int => quote! { #f: int(*values.get(#i)?)?, },
            VarType::Float | VarType::Time => quote! { #f: *values.get(#i)?, },
        });
        let has_int = vars.iter().any(|v| v.ty == VarType::Int);
        let int_fn = if has_int {
            quote! {
                // An integral value inside the i64 range, or nothing.
                fn int(v: f64) -> ::core::option::Option<i64> {
                    if v.fract() == 0.0 && (-9_223_372_036_854_775_808.0..9_223_372_036_854_775_808.0).contains(&v) {
                        ::core::option::Option::Some(v as i64)
                    } else {
                        ::core::option::Option::None
                    }
                }
            }
        } else {
            TokenStream::new()
        };
        let values_arg = if n == 0 { quote!(_values) } else { quote!(values) };
        quote! {
            /// One state of a trace: the spec's state variables.
            #[derive(Clone, Copy, Debug, Default, PartialEq)]
            pub struct State {
                #(#decls)*
            }

            impl State {
                /// The number of state variables.
                pub const VARS: usize = #n;
                /// The variable names, in declaration order.
                pub const NAMES: [&'static str; #n] = [#(#names),*];

                /// The values in declaration order, as the runtime's traces hold them.
                pub fn values(&self) -> [f64; #n] {
                    [#(#values),*]
                }

                /// A state from values in declaration order; `None` when there are too few
                /// or an `int` value is not an integer.
                pub fn from_values(#values_arg: &[f64]) -> ::core::option::Option<State> {
                    #int_fn
                    ::core::option::Option::Some(State { #(#from)* })
                }
            }
        }
    }

    fn primitive_enum(&self) -> TokenStream {
        let variants = &self.prim_variants;
        let names: Vec<&str> = self.spec.primitives.iter().map(|p| p.name.as_str()).collect();
        let docs = self
            .spec
            .primitives
            .iter()
            .map(|p| doc_or(p.doc.as_deref(), &format!("The primitive option `{}`.", p.name)));
        let n = variants.len();
        let idx = 0..n;
        let (name_body, index_body) = if n == 0 {
            (quote!(match self {}), quote!(match self {}))
        } else {
            (
                quote!(match self { #(Primitive::#variants => #names,)* }),
                quote!(match self { #(Primitive::#variants => #idx,)* }),
            )
        };
        quote! {
            /// The primitive options: each reaches one region.
            #[allow(clippy::upper_case_acronyms)]
            #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
            pub enum Primitive {
                #(#docs #variants,)*
            }

            impl Primitive {
                /// Every primitive option, in declaration order.
                pub const ALL: [Primitive; #n] = [#(Primitive::#variants),*];

                /// The option's name in the spec.
                pub const fn name(self) -> &'static str {
                    #name_body
                }

                /// The option's index in [`Primitive::ALL`] (and in the runtime's spec).
                pub const fn index(self) -> usize {
                    #index_body
                }
            }
        }
    }

    fn options_enum(&self) -> TokenStream {
        let variants = &self.option_variants;
        let names: Vec<&str> = self.spec.options.iter().map(|o| o.name.as_str()).collect();
        let docs = self.spec.options.iter().map(|o| {
            let legs: Vec<&str> = o
                .sequence
                .iter()
                .filter_map(|&i| self.spec.primitives.get(i).map(|p| p.name.as_str()))
                .collect();
            doc_attrs(Some(&format!(" Runs {} in turn.", legs.join(", "))))
        });
        let seqs = self.spec.options.iter().map(|o| {
            let legs = o.sequence.iter().filter_map(|&i| self.prim_variants.get(i));
            quote!(&[#(Primitive::#legs),*])
        });
        let n = variants.len();
        let idx = 0..n;
        let (name_body, seq_body, index_body) = if n == 0 {
            (quote!(match self {}), quote!(match self {}), quote!(match self {}))
        } else {
            (
                quote!(match self { #(Options::#variants => #names,)* }),
                quote!(match self { #(Options::#variants => #seqs,)* }),
                quote!(match self { #(Options::#variants => #idx,)* }),
            )
        };
        quote! {
            /// The options set the options policy chooses among.
            #[allow(clippy::upper_case_acronyms)]
            #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
            pub enum Options {
                #(#docs #variants,)*
            }

            impl Options {
                /// Every option of the set, in the set's order.
                pub const ALL: [Options; #n] = [#(Options::#variants),*];

                /// The option's name, such as `AB`.
                pub const fn name(self) -> &'static str {
                    #name_body
                }

                /// The primitive options it runs, in order.
                pub const fn sequence(self) -> &'static [Primitive] {
                    #seq_body
                }

                /// The option's index in [`Options::ALL`] (and in the runtime's spec).
                pub const fn index(self) -> usize {
                    #index_body
                }
            }
        }
    }

    /// The lets module: a monitor module per valid let, and what they share: `__build`
    /// (every let's node, each added once), `__sig_<i>` (let `i`'s signal given the
    /// signals of the lets it uses) and `__signals` (the signals a formula needs, each let
    /// computed once, in dependency order). The code is linear in the spec: a let's code
    /// names the lets it uses, never their bodies.
    fn lets(&self) -> TokenStream {
        let hstl = &self.root;
        let kernels = quote!(#hstl::robustness::kernels::Kernels);
        let n = self.spec.lets.len();
        let valid: Vec<usize> =
            self.spec.let_order.iter().copied().filter(|&i| self.let_valid[i]).collect();
        let mods: TokenStream = valid
            .iter()
            .map(|&i| {
                let l = &self.spec.lets[i];
                let doc = doc_or(l.doc.as_deref(), &format!("The `let` `{}`.", l.name));
                let name = &self.let_names[i];
                self.monitor(
                    &l.formula,
                    Some(i),
                    &quote!(super),
                    &quote!(super::super::State),
                    &doc,
                    &quote!(#name),
                )
            })
            .collect();
        let sigs: TokenStream = valid
            .iter()
            .map(|&i| {
                let f = &self.spec.lets[i].formula;
                let lets = quote!(self);
                let mut b = Body::new(self, &lets);
                let body = b.block(f);
                let k = if b.uses_kernels { quote!(k) } else { quote!(_k) };
                let name = format_ident!("__sig_{}", i);
                quote! {
                    #[doc(hidden)]
                    #[allow(unused_variables)]
                    pub fn #name(trace: &[super::State], #k: &mut #kernels, __l: &[::std::vec::Vec<f64>]) -> ::std::vec::Vec<f64> {
                        let __off = 0usize;
                        #body
                    }
                }
            })
            .collect();
        let deps = (0..n).map(|i| {
            let valid = self.let_valid[i];
            let d = if valid { self.signal_deps(&self.spec.lets[i].formula) } else { Vec::new() };
            quote!(&[#(#d),*])
        });
        let ats: TokenStream = valid
            .iter()
            .filter(|&&i| self.let_leaf[i])
            .map(|&i| {
                let lets = quote!(self);
                let mut b = Body::new(self, &lets);
                let p = b.point(&self.spec.lets[i].formula);
                let arg = if b.uses_state { quote!(s) } else { quote!(_s) };
                let name = format_ident!("__at_{}", i);
                quote! {
                    #[doc(hidden)]
                    #[inline]
                    pub fn #name(#arg: &super::State) -> f64 {
                        #p
                    }
                }
            })
            .collect();
        let arms = valid.iter().map(|&i| {
            let name = format_ident!("__sig_{}", i);
            quote!(#i => #name(trace, k, &__l),)
        });
        let build = self.build_lets();
        quote! {
            #build
            #ats
            #sigs

            #[doc(hidden)]
            /// The signals of the lets `roots` name and of every let they use, each
            /// computed once; the others are left empty.
            pub fn __signals(trace: &[super::State], k: &mut #kernels, roots: &[usize]) -> ::std::vec::Vec<::std::vec::Vec<f64>> {
                const DEPS: &[&[usize]] = &[#(#deps),*];
                const ORDER: &[usize] = &[#(#valid),*];
                let mut need = ::std::vec![false; #n];
                let mut stack: ::std::vec::Vec<usize> = roots.to_vec();
                while let ::core::option::Option::Some(i) = stack.pop() {
                    if !need[i] {
                        need[i] = true;
                        stack.extend_from_slice(DEPS[i]);
                    }
                }
                let mut __l: ::std::vec::Vec<::std::vec::Vec<f64>> = ::std::vec![::std::vec::Vec::new(); #n];
                for &i in ORDER {
                    if need[i] {
                        #[allow(clippy::match_single_binding)]
                        let v = match i {
                            #(#arms)*
                            _ => ::std::vec::Vec::new(),
                        };
                        __l[i] = v;
                    }
                }
                __l
            }

            #mods
        }
    }

    /// A module of monitors for one formula: let `index`'s, or the task's (`None`).
    /// `lets` is the path of the lets module seen from inside it.
    fn monitor(
        &self,
        f: &CFormula,
        index: Option<usize>,
        lets: &TokenStream,
        state: &TokenStream,
        doc: &TokenStream,
        name: &TokenStream,
    ) -> TokenStream {
        let hstl = &self.root;
        let data = match index {
            Some(i) => quote! {{
                let mut __b = #hstl::robustness::FormulaBuilder::new();
                let __l = #lets::__build(&mut __b);
                __b.build(__l[#i])
            }},
            None => self.formula_expr(f, lets),
        };
        let empty = lit_f64(self.empty_value(f));
        let kernels = quote!(#hstl::robustness::kernels::Kernels);
        // The lets the monitor reads (each computed once by `__signals`).
        let roots: Vec<usize> = match index {
            Some(i) => vec![i],
            None => self.signal_deps(f),
        };
        // A leaf state let: its fused expression, and no signal of another let.
        if let Some(i) = index
            && self.let_leaf[i]
        {
            return self.leaf_monitor(i, f, lets, state, doc, name, data);
        }
        let signals = |trace: TokenStream, k: TokenStream| {
            if roots.is_empty() {
                TokenStream::new()
            } else {
                quote!(let __l = #lets::__signals(#trace, #k, &[#(#roots),*]);)
            }
        };
        let (at, signal_with, robustness) = if self.spec.is_state_formula(f) {
            let (arg, p) = match index {
                Some(i) => (quote!(s), quote!(__l[#i][0])),
                None => {
                    let mut b = Body::new(self, lets);
                    let p = b.point(f);
                    let arg =
                        if b.uses_state || !roots.is_empty() { quote!(s) } else { quote!(_s) };
                    (arg, p)
                }
            };
            let prelude = signals(quote!(::core::slice::from_ref(s)), quote!(&mut #kernels::new()));
            let at = quote! {
                /// Robustness on one state (a state formula reads no other).
                #[allow(unused_variables)]
                pub fn at(#arg: &#state) -> f64 {
                    #prelude
                    let (__off, __t) = (0usize, 0usize);
                    #p
                }
            };
            let signal_with = match index {
                Some(i) => quote! {
                    /// [`signal`] with the caller's kernel buffers.
                    pub fn signal_with(trace: &[#state], k: &mut #kernels) -> ::std::vec::Vec<f64> {
                        let mut __l = #lets::__signals(trace, k, &[#i]);
                        ::core::mem::take(&mut __l[#i])
                    }
                },
                None if roots.is_empty() => quote! {
                    /// [`signal`]; a state formula needs no kernels.
                    pub fn signal_with(trace: &[#state], _k: &mut #kernels) -> ::std::vec::Vec<f64> {
                        trace.iter().map(at).collect()
                    }
                },
                None => {
                    let mut b = Body::new(self, lets);
                    let body = b.block(f);
                    let prelude = signals(quote!(trace), quote!(k));
                    quote! {
                        /// [`signal`] with the caller's kernel buffers: the lets it reads
                        /// are computed once for the whole trace.
                        pub fn signal_with(trace: &[#state], k: &mut #kernels) -> ::std::vec::Vec<f64> {
                            #prelude
                            let __off = 0usize;
                            #body
                        }
                    }
                }
            };
            let robustness = quote!(trace.first().map_or(#empty, at));
            (at, signal_with, robustness)
        } else {
            let signal_with = match index {
                Some(i) => quote! {
                    /// [`signal`] with the caller's kernel buffers: reused over many calls,
                    /// they are allocated once.
                    pub fn signal_with(trace: &[#state], k: &mut #kernels) -> ::std::vec::Vec<f64> {
                        let mut __l = #lets::__signals(trace, k, &[#i]);
                        ::core::mem::take(&mut __l[#i])
                    }
                },
                None => {
                    let mut b = Body::new(self, lets);
                    let body = b.block(f);
                    let k =
                        if b.uses_kernels || !roots.is_empty() { quote!(k) } else { quote!(_k) };
                    let prelude = signals(quote!(trace), quote!(k));
                    quote! {
                        /// [`signal`] with the caller's kernel buffers: reused over many calls,
                        /// they are allocated once.
                        pub fn signal_with(trace: &[#state], #k: &mut #kernels) -> ::std::vec::Vec<f64> {
                            #prelude
                            let __off = 0usize;
                            #body
                        }
                    }
                }
            };
            // With a finite horizon `H`, step 0 reads only the first `H + 1` steps.
            let steps =
                self.horizon(f).and_then(|h| h.checked_add(1)).map(Literal::usize_unsuffixed);
            let robustness = match steps {
                Some(h) => quote! {
                    signal(&trace[..trace.len().min(#h)]).first().copied().unwrap_or(#empty)
                },
                None => quote!(signal(trace).first().copied().unwrap_or(#empty)),
            };
            (TokenStream::new(), signal_with, robustness)
        };
        quote! {
            #doc
            pub mod #name {
                #at

                /// The formula as the runtime's data.
                pub fn formula() -> #hstl::robustness::Formula {
                    #data
                }

                /// Robustness at every step of the trace. States are taken as given: a NaN
                /// field, or an expression that computes NaN, is skipped by the mins and
                /// maxes (the NaN policy of `hstl::robustness::offline`); refuse such a trace
                /// first with `hstl::robustness::nan` where it can occur.
                pub fn signal(trace: &[#state]) -> ::std::vec::Vec<f64> {
                    signal_with(trace, &mut #kernels::new())
                }

                #signal_with

                /// Robustness of the trace: at step 0 (what the reference evaluator gives
                /// for an empty trace when it is empty). NaN as for [`signal`].
                pub fn robustness(trace: &[#state]) -> f64 {
                    #robustness
                }

                /// Monitors the formula on states pushed one at a time (the runtime's
                /// streaming monitor over [`formula`]).
                #[derive(Clone, Debug)]
                pub struct Online {
                    monitor: #hstl::robustness::OnlineMonitor,
                }

                impl Online {
                    /// A monitor at step 0.
                    pub fn new() -> Online {
                        Online { monitor: #hstl::robustness::OnlineMonitor::new(&formula(), <#state>::VARS) }
                    }

                    /// Appends one state; returns the verdict it completes, if any.
                    pub fn push(&mut self, state: &#state) -> ::core::option::Option<#hstl::robustness::Verdict> {
                        // The row always has VARS values, so the monitor cannot refuse it.
                        self.monitor.push(&state.values()).ok().flatten()
                    }

                    /// The value the first open step would get if the trace ended now.
                    pub fn provisional(&mut self) -> ::core::option::Option<f64> {
                        self.monitor.provisional()
                    }

                    /// Ends the trace: the verdicts of every open step; the monitor then
                    /// starts a new trace.
                    pub fn finish(&mut self) -> ::std::vec::Vec<#hstl::robustness::Verdict> {
                        self.monitor.finish()
                    }

                    /// Steps a verdict lags behind the last pushed state; `None` when
                    /// unbounded.
                    pub fn horizon(&self) -> ::core::option::Option<usize> {
                        self.monitor.horizon()
                    }
                }

                impl ::core::default::Default for Online {
                    fn default() -> Online {
                        Online::new()
                    }
                }
            }
        }
    }

    /// The formula's horizon as the runtime computes it (`Formula::horizon`): the steps
    /// after `t` that `rho(f, t)` reads; `None` when unbounded (or past `usize`).
    fn horizon(&self, f: &CFormula) -> Option<usize> {
        let end = |iv: &Interval| match iv.end {
            Bound::Unbounded => None,
            Bound::Exclusive(b) => usize::try_from(b.saturating_sub(1)).ok(),
            Bound::Inclusive(b) => usize::try_from(b).ok(),
        };
        match &f.kind {
            CFormulaKind::True
            | CFormulaKind::False
            | CFormulaKind::Cmp(..)
            | CFormulaKind::Invalid => Some(0),
            CFormulaKind::Let(i) => self.let_horizon.get(*i).copied().flatten(),
            CFormulaKind::Not(a) => self.horizon(a),
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                v.iter().try_fold(0, |acc, g| self.horizon(g).map(|h| acc.max(h)))
            }
            CFormulaKind::Implies(a, b) => Some(self.horizon(a)?.max(self.horizon(b)?)),
            CFormulaKind::Always(iv, a) | CFormulaKind::Eventually(iv, a) => {
                end(iv)?.checked_add(self.horizon(a)?)
            }
            CFormulaKind::Until(iv, a, b) => {
                end(iv)?.checked_add(self.horizon(a)?.max(self.horizon(b)?))
            }
            // Past windows never look forward.
            CFormulaKind::Once(_, a) | CFormulaKind::Historically(_, a) | CFormulaKind::Prev(a) => {
                self.horizon(a)
            }
            CFormulaKind::Since(_, a, b) => Some(self.horizon(a)?.max(self.horizon(b)?)),
            CFormulaKind::Next(a) => self.horizon(a)?.checked_add(1),
        }
    }

    /// The reference evaluator's `rho(f, 0)` on an empty trace.
    fn empty_value(&self, f: &CFormula) -> f64 {
        match &f.kind {
            CFormulaKind::True | CFormulaKind::Always(..) => f64::INFINITY,
            CFormulaKind::False | CFormulaKind::Eventually(..) | CFormulaKind::Until(..) => {
                f64::NEG_INFINITY
            }
            CFormulaKind::Cmp(..) | CFormulaKind::Invalid => f64::NAN,
            CFormulaKind::Let(i) => self.let_empty.get(*i).copied().unwrap_or(f64::NAN),
            CFormulaKind::Not(a) => -self.empty_value(a),
            CFormulaKind::And(v) => {
                v.iter().map(|g| self.empty_value(g)).fold(f64::INFINITY, f64::min)
            }
            CFormulaKind::Or(v) => {
                v.iter().map(|g| self.empty_value(g)).fold(f64::NEG_INFINITY, f64::max)
            }
            CFormulaKind::Implies(a, b) => (-self.empty_value(a)).max(self.empty_value(b)),
            CFormulaKind::Historically(..) | CFormulaKind::Prev(..) | CFormulaKind::Next(..) => {
                f64::INFINITY
            }
            CFormulaKind::Once(..) | CFormulaKind::Since(..) => f64::NEG_INFINITY,
        }
    }

    /// Statements adding `f` to the builder `__b` (the lets' nodes in `__l`), one node
    /// a statement: no nesting, however deep `f` is. Returns the variable of its node.
    fn formula_data(&self, f: &CFormula, out: &mut Data) -> Ident {
        let hstl = &self.root;
        let rob = quote!(#hstl::robustness);
        let node = match &f.kind {
            CFormulaKind::True => quote!(__b.bool(true)),
            CFormulaKind::False | CFormulaKind::Invalid => quote!(__b.bool(false)),
            CFormulaKind::Let(i) => quote!(__l[#i]),
            CFormulaKind::Cmp(op, a, b) => {
                let op = match op {
                    CmpOp::Lt => quote!(Lt),
                    CmpOp::Le => quote!(Le),
                    CmpOp::Gt => quote!(Gt),
                    CmpOp::Ge => quote!(Ge),
                };
                let (a, b) = (out.expr(a), out.expr(b));
                quote!(__b.cmp(#a, #rob::CmpOp::#op, #b))
            }
            CFormulaKind::Not(a) => {
                let a = self.formula_data(a, out);
                quote!(__b.not(#a))
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                let parts: Vec<Ident> = v.iter().map(|g| self.formula_data(g, out)).collect();
                let kind =
                    if matches!(f.kind, CFormulaKind::And(_)) { quote!(and) } else { quote!(or) };
                quote!(__b.#kind(::std::vec![#(#parts),*]))
            }
            CFormulaKind::Implies(a, b) => {
                let (a, b) = (self.formula_data(a, out), self.formula_data(b, out));
                quote!(__b.implies(#a, #b))
            }
            CFormulaKind::Always(iv, a) | CFormulaKind::Eventually(iv, a) => {
                let kind = if matches!(f.kind, CFormulaKind::Always(..)) {
                    quote!(always)
                } else {
                    quote!(eventually)
                };
                let (iv, a) = (interval_data(iv, hstl), self.formula_data(a, out));
                quote!(__b.#kind(#iv, #a))
            }
            CFormulaKind::Until(iv, a, b) => {
                let iv = interval_data(iv, hstl);
                let (a, b) = (self.formula_data(a, out), self.formula_data(b, out));
                quote!(__b.until(#iv, #a, #b))
            }
            CFormulaKind::Once(iv, a) | CFormulaKind::Historically(iv, a) => {
                let kind = if matches!(f.kind, CFormulaKind::Once(..)) {
                    quote!(once)
                } else {
                    quote!(historically)
                };
                let (iv, a) = (interval_data(iv, hstl), self.formula_data(a, out));
                quote!(__b.#kind(#iv, #a))
            }
            CFormulaKind::Since(iv, a, b) => {
                let iv = interval_data(iv, hstl);
                let (a, b) = (self.formula_data(a, out), self.formula_data(b, out));
                quote!(__b.since(#iv, #a, #b))
            }
            CFormulaKind::Prev(a) | CFormulaKind::Next(a) => {
                let kind = if matches!(f.kind, CFormulaKind::Prev(..)) {
                    quote!(prev)
                } else {
                    quote!(next)
                };
                let a = self.formula_data(a, out);
                quote!(__b.#kind(#a))
            }
        };
        out.push(node)
    }

    /// The lets module's `__build`: every valid let added to a builder once, in
    /// dependency order; `__l[i]` is let `i`'s node (`false` for a let that did not check,
    /// which no generated formula uses).
    fn build_lets(&self) -> TokenStream {
        let hstl = &self.root;
        let n = self.spec.lets.len();
        let mut data = Data::default();
        let mut stmts = Vec::new();
        for &i in &self.spec.let_order {
            if !self.let_valid[i] {
                continue;
            }
            let id = self.formula_data(&self.spec.lets[i].formula, &mut data);
            let body = data.take();
            stmts.push(quote! { { #(#body)* __l[#i] = #id; } });
        }
        quote! {
            #[doc(hidden)]
            /// Every valid let into `__b`, each once; the node of let `i` at index `i`.
            pub fn __build(__b: &mut #hstl::robustness::FormulaBuilder) -> ::std::vec::Vec<#hstl::robustness::NodeId> {
                let __false = __b.bool(false);
                #[allow(unused_mut)]
                let mut __l = ::std::vec![__false; #n];
                #(#stmts)*
                __l
            }
        }
    }

    /// Code evaluating to the runtime's `Formula` of `f`, built with the lets module at
    /// `lets`.
    fn formula_expr(&self, f: &CFormula, lets: &TokenStream) -> TokenStream {
        let hstl = &self.root;
        let mut data = Data::default();
        let id = self.formula_data(f, &mut data);
        let body = data.take();
        quote! {{
            let mut __b = #hstl::robustness::FormulaBuilder::new();
            let __l = #lets::__build(&mut __b);
            #(#body)*
            __b.build(#id)
        }}
    }

    /// The lets `f` names whose signals it reads (the leaf state lets are fused instead).
    fn signal_deps(&self, f: &CFormula) -> Vec<usize> {
        let leaf = |i: usize| self.let_leaf.get(i).copied().unwrap_or(false);
        let_deps(f).into_iter().filter(|&i| !leaf(i)).collect()
    }

    /// The monitors of leaf state let `i`: its fused expression on each state.
    #[allow(clippy::too_many_arguments)]
    fn leaf_monitor(
        &self,
        i: usize,
        f: &CFormula,
        lets: &TokenStream,
        state: &TokenStream,
        doc: &TokenStream,
        name: &TokenStream,
        data: TokenStream,
    ) -> TokenStream {
        let hstl = &self.root;
        let kernels = quote!(#hstl::robustness::kernels::Kernels);
        let empty = lit_f64(self.empty_value(f));
        let at = format_ident!("__at_{}", i);
        quote! {
            #doc
            pub mod #name {
                /// Robustness on one state (a state formula reads no other).
                pub fn at(s: &#state) -> f64 {
                    #lets::#at(s)
                }

                /// The formula as the runtime's data.
                pub fn formula() -> #hstl::robustness::Formula {
                    #data
                }

                /// Robustness at every step of the trace.
                pub fn signal(trace: &[#state]) -> ::std::vec::Vec<f64> {
                    trace.iter().map(at).collect()
                }

                /// [`signal`]; a state formula needs no kernels.
                pub fn signal_with(trace: &[#state], _k: &mut #kernels) -> ::std::vec::Vec<f64> {
                    signal(trace)
                }

                /// Robustness of the trace: at step 0 (what the reference evaluator gives
                /// for an empty trace when it is empty).
                pub fn robustness(trace: &[#state]) -> f64 {
                    trace.first().map_or(#empty, at)
                }

                /// Monitors the formula on states pushed one at a time (the runtime's
                /// streaming monitor over [`formula`]).
                #[derive(Clone, Debug)]
                pub struct Online {
                    monitor: #hstl::robustness::OnlineMonitor,
                }

                impl Online {
                    /// A monitor at step 0.
                    pub fn new() -> Online {
                        Online { monitor: #hstl::robustness::OnlineMonitor::new(&formula(), <#state>::VARS) }
                    }

                    /// Appends one state; returns the verdict it completes, if any.
                    pub fn push(&mut self, state: &#state) -> ::core::option::Option<#hstl::robustness::Verdict> {
                        // The row always has VARS values, so the monitor cannot refuse it.
                        self.monitor.push(&state.values()).ok().flatten()
                    }

                    /// The value the first open step would get if the trace ended now.
                    pub fn provisional(&mut self) -> ::core::option::Option<f64> {
                        self.monitor.provisional()
                    }

                    /// Ends the trace: the verdicts of every open step; the monitor then
                    /// starts a new trace.
                    pub fn finish(&mut self) -> ::std::vec::Vec<#hstl::robustness::Verdict> {
                        self.monitor.finish()
                    }

                    /// Steps a verdict lags behind the last pushed state; `None` when
                    /// unbounded.
                    pub fn horizon(&self) -> ::core::option::Option<usize> {
                        self.monitor.horizon()
                    }
                }

                impl ::core::default::Default for Online {
                    fn default() -> Online {
                        Online::new()
                    }
                }
            }
        }
    }

    fn spec_impl(&self, src: &str) -> TokenStream {
        let hstl = &self.root;
        let Some(task) = &self.spec.task else { return TokenStream::new() };
        if !self.valid(&task.formula) {
            return TokenStream::new();
        }
        // The unit struct is named after the spec, unless that names another item here.
        let camel = camel_case(&self.spec.name);
        let ty = match camel.as_str() {
            "State" | "Primitive" | "Options" => format_ident!("{}Spec", camel),
            _ => ident(&camel),
        };
        let name = &self.spec.name;
        // Every formula of the spec goes into one builder: the lets' nodes are shared.
        let mut data = Data::default();
        let task_id = self.formula_data(&task.formula, &mut data);
        let vars = self.spec.state_vars.iter().map(|v| {
            let name = &v.name;
            let domain = match v.domain {
                Domain::Int { lo, hi } => quote!(::core::option::Option::Some(#lo..=#hi)),
                _ => quote!(::core::option::Option::None),
            };
            quote!(#hstl::runtime::StateVar { name: ::std::string::String::from(#name), domain: #domain })
        });
        let prims = self.spec.primitives.iter().map(|p| {
            let name = &p.name;
            let reach = self.formula_data(&p.reach, &mut data);
            let init = self.formula_data(&p.init, &mut data);
            let terminate = match &p.terminate {
                Terminate::Argmax => quote!(#hstl::runtime::Terminate::Argmax),
                Terminate::Formula(f) => {
                    let f = self.formula_data(f, &mut data);
                    quote!(#hstl::runtime::Terminate::Formula(__b.build(#f)))
                }
            };
            let avoid = match &p.avoid {
                Some(f) => {
                    let f = self.formula_data(f, &mut data);
                    quote!(::core::option::Option::Some(__b.build(#f)))
                }
                None => quote!(::core::option::Option::None),
            };
            quote! {
                #hstl::runtime::PrimitiveOption {
                    name: ::std::string::String::from(#name),
                    reach: __b.build(#reach),
                    init: __b.build(#init),
                    terminate: #terminate,
                    avoid: #avoid,
                }
            }
        });
        let options = self.spec.options.iter().map(|o| {
            let name = &o.name;
            let seq = &o.sequence;
            quote! {
                #hstl::runtime::CombinedOption {
                    name: ::std::string::String::from(#name),
                    sequence: ::std::vec![#(#seq),*],
                }
            }
        });
        let prims: Vec<TokenStream> = prims.collect();
        let regions =
            self.spec.persistent_conjuncts(src).unwrap_or_default().into_iter().map(|c| {
                let name = c.name;
                let formula = self.formula_data(&c.region, &mut data);
                let steps = Literal::u64_unsuffixed(c.steps);
                quote! {
                    #hstl::runtime::Region {
                        name: ::std::string::String::from(#name),
                        formula: __b.build(#formula),
                        horizon: #steps,
                    }
                }
            });
        let regions: Vec<TokenStream> = regions.collect();
        let stmts = data.take();
        let l = &self.spec.learn;
        let level = |q: &hstl_lang::QParams| {
            let (g, a, e, m, d) = (
                lit_f64(q.gamma),
                lit_f64(q.alpha),
                lit_f64(q.epsilon),
                lit_f64(q.min_epsilon),
                lit_f64(q.decay),
            );
            quote! {
                #hstl::runtime::LevelParams { gamma: #g, alpha: #a, epsilon: #e, min_epsilon: #m, decay: #d }
            }
        };
        let (flat, opts) = (level(&l.flat), level(&l.options));
        let (episodes, choices, max_steps, memory) = (
            Literal::u64_unsuffixed(l.episodes),
            Literal::u64_unsuffixed(l.choices),
            Literal::u64_unsuffixed(l.max_steps),
            Literal::u64_unsuffixed(l.memory),
        );
        let counterfactual = Literal::u64_unsuffixed(l.counterfactual);
        let intra = match l.intra {
            hstl_lang::Intra::Paper => quote!(Paper),
            hstl_lang::Intra::Remaining => quote!(Remaining),
        };
        let switch = match l.switch {
            hstl_lang::Switch::Termination => quote!(Termination),
            hstl_lang::Switch::Step => quote!(Step),
        };
        let plan = match l.plan {
            hstl_lang::Plan::Off => quote!(Off),
            hstl_lang::Plan::Model => quote!(Model),
        };
        let reward = match l.reward {
            hstl_lang::Reward::Segment => quote!(Segment),
            hstl_lang::Reward::Window => quote!(Window),
        };
        let tiles = match self.spec.tile_box() {
            Some(b) => {
                let tilings = b.tilings as usize;
                let bins = b.bins.iter().map(|&n| n as usize);
                let (lo, hi) = (&b.lo, &b.hi);
                quote!(::core::option::Option::Some(#hstl::runtime::TileParams {
                    tilings: #tilings,
                    bins: ::std::vec![#(#bins),*],
                    lo: ::std::vec![#(#lo),*],
                    hi: ::std::vec![#(#hi),*],
                }))
            }
            None => quote!(::core::option::Option::None),
        };
        let doc =
            format!(" The spec `{name}` for the runtime: train it with `hstl::runtime::Learner`.");
        quote! {
            #[doc = #doc]
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct #ty;

            impl #ty {
                /// The spec as the runtime's plain data.
                pub fn task_spec() -> #hstl::runtime::TaskSpec {
                    let mut __b = #hstl::robustness::FormulaBuilder::new();
                    let __l = lets::__build(&mut __b);
                    #(#stmts)*
                    #hstl::runtime::TaskSpec {
                        name: ::std::string::String::from(#name),
                        state_vars: ::std::vec![#(#vars),*],
                        task: __b.build(#task_id),
                        primitives: ::std::vec![#(#prims),*],
                        options: ::std::vec![#(#options),*],
                        learn: #hstl::runtime::LearnParams {
                            episodes: #episodes,
                            choices: #choices,
                            max_steps: #max_steps,
                            memory: #memory,
                            intra: #hstl::runtime::Intra::#intra,
                            reward: #hstl::runtime::RewardKind::#reward,
                            counterfactual: #counterfactual,
                            switch: #hstl::runtime::Switch::#switch,
                            plan: #hstl::runtime::Plan::#plan,
                            flat: #flat,
                            options: #opts,
                            tiles: #tiles,
                        },
                        regions: ::std::vec![#(#regions),*],
                    }
                }
            }

            impl #hstl::runtime::Spec for #ty {
                fn task_spec(&self) -> #hstl::runtime::TaskSpec {
                    #ty::task_spec()
                }
            }
        }
    }
}

/// Whether `f` has a past-time operator (not looking through lets, whose signals are
/// computed over the whole trace). The walk keeps its own stack.
fn has_past_node(f: &CFormula) -> bool {
    let mut stack = vec![f];
    while let Some(f) = stack.pop() {
        match &f.kind {
            CFormulaKind::Once(..)
            | CFormulaKind::Historically(..)
            | CFormulaKind::Since(..)
            | CFormulaKind::Prev(..) => return true,
            CFormulaKind::Not(a)
            | CFormulaKind::Always(_, a)
            | CFormulaKind::Eventually(_, a)
            | CFormulaKind::Next(a) => stack.push(a),
            CFormulaKind::And(v) | CFormulaKind::Or(v) => stack.extend(v),
            CFormulaKind::Implies(a, b) | CFormulaKind::Until(_, a, b) => {
                stack.extend([&**a, &**b])
            }
            CFormulaKind::True
            | CFormulaKind::False
            | CFormulaKind::Let(_)
            | CFormulaKind::Cmp(..)
            | CFormulaKind::Invalid => {}
        }
    }
    false
}

/// Code for one formula's signal over `trace` (a `&[State]`), with the kernels `k` in
/// scope: one `let` statement per operator. State subformulas become one fused expression
/// per step, mapped over the trace; the temporal structure goes to the offline evaluator's
/// kernels (`hstl::robustness::kernels`), piece by piece where the horizon is finite, as
/// the evaluator itself runs it.
struct Body<'g, 'a> {
    g: &'g Gen<'a>,
    /// The path of the lets module (its `__at_<i>` functions).
    lets: &'g TokenStream,
    /// The statements of the block being written (a closure body opens a new one).
    stmts: Vec<TokenStream>,
    /// The number of `sig<n>` variables so far.
    vars: usize,
    uses_state: bool,
    uses_kernels: bool,
}

/// A signal in generated code: a `let mut` variable, or an expression of type `Vec<f64>`.
enum Sig {
    Var(Ident),
    Expr(TokenStream),
}

impl Sig {
    fn tokens(&self) -> TokenStream {
        match self {
            Sig::Var(v) => quote!(#v),
            Sig::Expr(e) => e.clone(),
        }
    }
}

impl<'g, 'a> Body<'g, 'a> {
    fn new(g: &'g Gen<'a>, lets: &'g TokenStream) -> Body<'g, 'a> {
        Body { g, lets, stmts: Vec::new(), vars: 0, uses_state: false, uses_kernels: false }
    }

    /// The statements and the final expression of the signal of `f`.
    fn block(&mut self, f: &CFormula) -> TokenStream {
        let sig = self.signal(f, false).tokens();
        let stmts = std::mem::take(&mut self.stmts);
        quote!(#(#stmts)* #sig)
    }

    /// A `let mut` variable holding `sig`.
    fn var(&mut self, sig: Sig) -> Ident {
        match sig {
            Sig::Var(v) => v,
            Sig::Expr(e) => {
                let v = format_ident!("sig{}", self.vars);
                self.vars += 1;
                self.stmts.push(quote!(let mut #v: ::std::vec::Vec<f64> = #e;));
                v
            }
        }
    }

    /// The signal of `f` on `trace`. `in_piece` says whether an enclosing formula is
    /// already evaluated piece by piece.
    fn signal(&mut self, f: &CFormula, in_piece: bool) -> Sig {
        if self.g.spec.is_state_formula(f) {
            return Sig::Expr(self.map(&[f], None));
        }
        self.uses_kernels = true;
        // A past-time operator reads back to step 0: no piece may hold one (a let's
        // signal is its own, computed over the whole trace).
        let whole = in_piece || has_past_node(f);
        match (&f.kind, whole, self.g.horizon(f)) {
            // A let runs its own pieces.
            (CFormulaKind::Let(_), ..) | (_, true, _) | (_, false, None) => {
                self.operator(f, in_piece)
            }
            (_, false, Some(h)) => {
                let hstl = &self.g.root;
                let outer = std::mem::take(&mut self.stmts);
                let sig = self.operator(f, true).tokens();
                let stmts = std::mem::replace(&mut self.stmts, outer);
                let h = Literal::usize_unsuffixed(h);
                Sig::Expr(quote! {
                    #hstl::robustness::kernels::pieces(trace.len(), #h, |steps| {
                        let __off = steps.start;
                        let trace = &trace[steps];
                        #(#stmts)*
                        #sig
                    })
                })
            }
        }
    }

    /// `trace.iter().map(..).collect()`: one expression per step, the state formula `fs[0]`
    /// alone when `fold` is `None`, else all of `fs` folded from the identity with `min`
    /// (`Some(true)`) or `max`, which drops NaN.
    fn map(&mut self, fs: &[&CFormula], fold: Option<bool>) -> TokenStream {
        // A `let` alone: its signal, computed once for the whole trace.
        if let ([f], None) = (fs, fold)
            && let CFormulaKind::Let(i) = f.kind
        {
            if self.g.let_leaf[i] {
                let (lets, at) = (self.lets, format_ident!("__at_{}", i));
                return quote!(trace.iter().map(#lets::#at).collect::<::std::vec::Vec<f64>>());
            }
            return quote!(__l[#i][__off..__off + trace.len()].to_vec());
        }
        let before = self.uses_state;
        self.uses_state = false;
        let p = match (fs, fold) {
            ([f, ..], None) => self.point(f),
            ([], None) => quote!(f64::NAN),
            (_, Some(and)) => {
                let ps: Vec<TokenStream> = fs.iter().map(|g| self.point(g)).collect();
                fold_parts(&ps, and)
            }
        };
        let arg = if self.uses_state { quote!(s) } else { quote!(_) };
        self.uses_state = before;
        quote!(trace.iter().enumerate().map(|(__t, #arg)| #p).collect::<::std::vec::Vec<f64>>())
    }

    /// [`Body::signal`] of a formula that is not a state formula, without pieces.
    fn operator(&mut self, f: &CFormula, in_piece: bool) -> Sig {
        let hstl = &self.g.root;
        let kernels = quote!(#hstl::robustness::kernels);
        match &f.kind {
            CFormulaKind::Let(i) if self.g.let_leaf[*i] => Sig::Expr(self.map(&[f], None)),
            CFormulaKind::Let(i) => Sig::Expr(quote!(__l[#i][__off..__off + trace.len()].to_vec())),
            CFormulaKind::Always(iv, a) | CFormulaKind::Eventually(iv, a) => {
                let a = self.signal(a, in_piece);
                let v = self.var(a);
                let iv = interval_data(iv, hstl);
                let op = if matches!(f.kind, CFormulaKind::Always(..)) {
                    quote!(always)
                } else {
                    quote!(eventually)
                };
                self.stmts.push(quote!(k.#op(&#iv, &mut #v);));
                Sig::Var(v)
            }
            CFormulaKind::Until(iv, a, b) | CFormulaKind::Since(iv, a, b) => {
                let a = self.signal(a, in_piece);
                let a = self.var(a);
                let b = self.signal(b, in_piece);
                let b = self.var(b);
                let iv = interval_data(iv, hstl);
                let op = if matches!(f.kind, CFormulaKind::Until(..)) {
                    quote!(until)
                } else {
                    quote!(since)
                };
                self.stmts.push(quote!(k.#op(&#iv, &mut #a, &mut #b);));
                Sig::Var(b)
            }
            CFormulaKind::Once(iv, a) | CFormulaKind::Historically(iv, a) => {
                let a = self.signal(a, in_piece);
                let v = self.var(a);
                let iv = interval_data(iv, hstl);
                let op = if matches!(f.kind, CFormulaKind::Once(..)) {
                    quote!(once)
                } else {
                    quote!(historically)
                };
                self.stmts.push(quote!(k.#op(&#iv, &mut #v);));
                Sig::Var(v)
            }
            CFormulaKind::Prev(a) | CFormulaKind::Next(a) => {
                let a = self.signal(a, in_piece);
                let v = self.var(a);
                let op = if matches!(f.kind, CFormulaKind::Prev(..)) {
                    quote!(prev)
                } else {
                    quote!(next)
                };
                self.stmts.push(quote!(k.#op(&mut #v);));
                Sig::Var(v)
            }
            CFormulaKind::Not(a) => {
                let a = self.signal(a, in_piece);
                let v = self.var(a);
                self.stmts.push(quote! {
                    for x in #v.iter_mut() {
                        *x = -*x;
                    }
                });
                Sig::Var(v)
            }
            CFormulaKind::Implies(a, b) => {
                let a = self.signal(a, in_piece);
                let v = self.var(a);
                let b = self.signal(b, in_piece).tokens();
                self.stmts.push(quote! {
                    for (x, y) in #v.iter_mut().zip(&#b) {
                        *x = (-*x).max(*y);
                    }
                });
                Sig::Var(v)
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                let and = matches!(f.kind, CFormulaKind::And(_));
                // The state operands fuse into one expression per step; the others are
                // folded in whole. Every signal here is NaN-free (a temporal operator's
                // skips NaN, and the fused operands start from the identity), as
                // `and_into` and `or_into` ask of their first argument.
                let (state, temporal): (Vec<&CFormula>, Vec<&CFormula>) =
                    v.iter().partition(|g| self.g.spec.is_state_formula(g));
                let mut parts = Vec::new();
                if !state.is_empty() {
                    parts.push(Sig::Expr(self.map(&state, Some(and))));
                }
                for g in temporal {
                    let sig = self.signal(g, in_piece);
                    parts.push(sig);
                }
                let mut parts = parts.into_iter();
                let Some(first) = parts.next() else {
                    // Not reached: a formula without operands is a state formula.
                    return Sig::Expr(self.map(&[], Some(and)));
                };
                let mut rest = parts.peekable();
                if rest.peek().is_none() {
                    return first;
                }
                let acc = self.var(first);
                let fold = if and { quote!(and_into) } else { quote!(or_into) };
                for sig in rest {
                    let sig = sig.tokens();
                    self.stmts.push(quote!(#kernels::#fold(&mut #acc, &#sig);));
                }
                Sig::Var(acc)
            }
            // State formulas are mapped in `signal`; invalid ones are not generated.
            CFormulaKind::True
            | CFormulaKind::False
            | CFormulaKind::Cmp(..)
            | CFormulaKind::Invalid => Sig::Expr(self.map(&[f], None)),
        }
    }

    /// An `f64` expression: `rho(f, t)` of a state formula on the state `s`.
    fn point(&mut self, f: &CFormula) -> TokenStream {
        match &f.kind {
            CFormulaKind::True => quote!(f64::INFINITY),
            CFormulaKind::False | CFormulaKind::Invalid => quote!(f64::NEG_INFINITY),
            CFormulaKind::Let(i) if self.g.let_leaf[*i] => {
                self.uses_state = true;
                let (lets, at) = (self.lets, format_ident!("__at_{}", i));
                quote!(#lets::#at(s))
            }
            CFormulaKind::Let(i) => quote!(__l[#i][__off + __t]),
            CFormulaKind::Cmp(op, a, b) => {
                self.uses_state |= reads_state(a) || reads_state(b);
                let (a, b) = (self.operand(a), self.operand(b));
                match op {
                    CmpOp::Lt | CmpOp::Le => quote!(#b - #a),
                    CmpOp::Gt | CmpOp::Ge => quote!(#a - #b),
                }
            }
            CFormulaKind::Not(a) => {
                let a = self.point(a);
                quote!(-(#a))
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                let parts: Vec<TokenStream> = v.iter().map(|g| self.point(g)).collect();
                fold_parts(&parts, matches!(f.kind, CFormulaKind::And(_)))
            }
            CFormulaKind::Implies(a, b) => {
                let (a, b) = (self.point(a), self.point(b));
                quote!((-(#a)).max(#b))
            }
            // Not reached: `point` is only asked for state formulas.
            CFormulaKind::Always(..)
            | CFormulaKind::Eventually(..)
            | CFormulaKind::Until(..)
            | CFormulaKind::Once(..)
            | CFormulaKind::Historically(..)
            | CFormulaKind::Since(..)
            | CFormulaKind::Prev(..)
            | CFormulaKind::Next(..) => quote!(f64::NAN),
        }
    }

    fn operand(&self, e: &CExpr) -> TokenStream {
        let x = self.expr(e);
        match e.kind {
            CExprKind::Const(c) if c >= 0.0 => x,
            _ => quote!((#x)),
        }
    }

    fn expr(&self, e: &CExpr) -> TokenStream {
        match &e.kind {
            CExprKind::Const(c) => lit_f64(*c),
            CExprKind::Invalid => quote!(f64::NAN),
            CExprKind::Var(i) => match self.g.spec.state_vars.get(*i) {
                Some(v) => {
                    let f = ident(&v.name);
                    match v.ty {
                        VarType::Int => quote!(s.#f as f64),
                        VarType::Float | VarType::Time => quote!(s.#f),
                    }
                }
                None => quote!(f64::NAN),
            },
            CExprKind::Neg(a) => {
                let a = self.operand(a);
                quote!(-#a)
            }
            CExprKind::Add(a, b)
            | CExprKind::Sub(a, b)
            | CExprKind::Mul(a, b)
            | CExprKind::Div(a, b) => {
                let (a, b) = (self.operand(a), self.operand(b));
                match e.kind {
                    CExprKind::Add(..) => quote!(#a + #b),
                    CExprKind::Sub(..) => quote!(#a - #b),
                    CExprKind::Mul(..) => quote!(#a * #b),
                    _ => quote!(#a / #b),
                }
            }
            CExprKind::Abs(a) => {
                let a = self.expr(a);
                quote!(f64::abs(#a))
            }
            CExprKind::Sqrt(a) => {
                let a = self.expr(a);
                quote!(f64::sqrt(#a))
            }
        }
    }
}

/// `rho` of `&&` (`and`) or `||` over operand expressions: `min` or `max` folded from
/// the identity, which drops a NaN operand as the evaluators do.
fn fold_parts(parts: &[TokenStream], and: bool) -> TokenStream {
    if and {
        quote!(f64::INFINITY #(.min(#parts))*)
    } else {
        quote!(f64::NEG_INFINITY #(.max(#parts))*)
    }
}

fn interval_data(iv: &Interval, hstl: &TokenStream) -> TokenStream {
    let start = Literal::u64_unsuffixed(iv.start);
    let end = match iv.end {
        Bound::Unbounded => quote!(#hstl::robustness::Bound::Unbounded),
        Bound::Exclusive(b) => {
            let b = Literal::u64_unsuffixed(b);
            quote!(#hstl::robustness::Bound::Exclusive(#b))
        }
        Bound::Inclusive(b) => {
            let b = Literal::u64_unsuffixed(b);
            quote!(#hstl::robustness::Bound::Inclusive(#b))
        }
    };
    quote!(#hstl::robustness::Interval { start: #start, end: #end })
}

/// Statements building formula nodes in generated code, one node each (see
/// [`Gen::formula_data`]).
#[derive(Default)]
struct Data {
    stmts: Vec<TokenStream>,
    vars: usize,
}

impl Data {
    /// A statement `let __n<k> = node;`; returns `__n<k>`.
    fn push(&mut self, node: TokenStream) -> Ident {
        let v = format_ident!("__n{}", self.vars);
        self.vars += 1;
        self.stmts.push(quote!(let #v = #node;));
        v
    }

    fn take(&mut self) -> Vec<TokenStream> {
        std::mem::take(&mut self.stmts)
    }

    /// Statements adding expression `e` to `__b`; returns the variable of its node.
    fn expr(&mut self, e: &CExpr) -> Ident {
        let node = match &e.kind {
            CExprKind::Const(c) => {
                let c = lit_f64(*c);
                quote!(__b.constant(#c))
            }
            CExprKind::Invalid => quote!(__b.constant(f64::NAN)),
            CExprKind::Var(i) => quote!(__b.var(#i)),
            CExprKind::Neg(a) | CExprKind::Abs(a) | CExprKind::Sqrt(a) => {
                let kind = match e.kind {
                    CExprKind::Neg(_) => quote!(neg),
                    CExprKind::Abs(_) => quote!(abs),
                    _ => quote!(sqrt),
                };
                let a = self.expr(a);
                quote!(__b.#kind(#a))
            }
            CExprKind::Add(a, b)
            | CExprKind::Sub(a, b)
            | CExprKind::Mul(a, b)
            | CExprKind::Div(a, b) => {
                let kind = match e.kind {
                    CExprKind::Add(..) => quote!(add_expr),
                    CExprKind::Sub(..) => quote!(sub_expr),
                    CExprKind::Mul(..) => quote!(mul_expr),
                    _ => quote!(div_expr),
                };
                let (a, b) = (self.expr(a), self.expr(b));
                quote!(__b.#kind(#a, #b))
            }
        };
        self.push(node)
    }
}

/// The lets `f` names directly, each once, in order of first use.
fn let_deps(f: &CFormula) -> Vec<usize> {
    let (mut out, mut seen) = (Vec::new(), HashSet::new());
    hstl_lang::visit_lets(f, &mut |i| {
        if seen.insert(i) {
            out.push(i);
        }
    });
    out
}

fn valid_expr(e: &CExpr) -> bool {
    match &e.kind {
        CExprKind::Invalid => false,
        CExprKind::Const(_) | CExprKind::Var(_) => true,
        CExprKind::Neg(a) | CExprKind::Abs(a) | CExprKind::Sqrt(a) => valid_expr(a),
        CExprKind::Add(a, b)
        | CExprKind::Sub(a, b)
        | CExprKind::Mul(a, b)
        | CExprKind::Div(a, b) => valid_expr(a) && valid_expr(b),
    }
}

fn reads_state(e: &CExpr) -> bool {
    match &e.kind {
        CExprKind::Var(_) => true,
        CExprKind::Const(_) | CExprKind::Invalid => false,
        CExprKind::Neg(a) | CExprKind::Abs(a) | CExprKind::Sqrt(a) => reads_state(a),
        CExprKind::Add(a, b)
        | CExprKind::Sub(a, b)
        | CExprKind::Mul(a, b)
        | CExprKind::Div(a, b) => reads_state(a) || reads_state(b),
    }
}

/// An `f64` literal that reads back as the same bits (negative numbers and infinities as
/// expressions).
fn lit_f64(x: f64) -> TokenStream {
    if x.is_nan() {
        quote!(f64::NAN)
    } else if x == f64::INFINITY {
        quote!(f64::INFINITY)
    } else if x == f64::NEG_INFINITY {
        quote!(f64::NEG_INFINITY)
    } else if x.is_sign_negative() {
        let l = Literal::f64_suffixed(-x);
        quote!((-#l))
    } else {
        let l = Literal::f64_suffixed(x);
        quote!(#l)
    }
}

fn rust_type(ty: VarType) -> TokenStream {
    match ty {
        VarType::Int => quote!(i64),
        VarType::Float | VarType::Time => quote!(f64),
    }
}

fn doc_attrs(doc: Option<&str>) -> TokenStream {
    match doc {
        Some(d) => {
            let lines = d
                .split('\n')
                .map(|l| if l.starts_with(' ') { l.to_string() } else { format!(" {l}") });
            quote!(#(#[doc = #lines])*)
        }
        None => TokenStream::new(),
    }
}

fn doc_or(doc: Option<&str>, fallback: &str) -> TokenStream {
    match doc {
        Some(d) if !d.trim().is_empty() => doc_attrs(Some(d)),
        _ => {
            let line = format!(" {fallback}");
            quote!(#[doc = #line])
        }
    }
}

/// A Rust identifier for a name: raw where a keyword allows it, with a trailing `_` where
/// it does not (`self`, `super`, `crate`, `Self`, `_`).
pub fn ident(name: &str) -> Ident {
    const KEYWORDS: &[&str] = &[
        "as", "async", "await", "break", "const", "continue", "dyn", "else", "enum", "extern",
        "false", "fn", "for", "gen", "if", "impl", "in", "let", "loop", "match", "mod", "move",
        "mut", "pub", "ref", "return", "static", "struct", "trait", "true", "type", "unsafe",
        "use", "where", "while", "abstract", "become", "box", "do", "final", "macro", "override",
        "priv", "try", "typeof", "unsized", "virtual", "yield",
    ];
    if matches!(name, "self" | "super" | "crate" | "Self" | "_") || name.is_empty() {
        format_ident!("{}_", name)
    } else if KEYWORDS.contains(&name) {
        Ident::new_raw(name, Span::call_site())
    } else {
        Ident::new(name, Span::call_site())
    }
}

fn unique(taken: &mut HashSet<String>, base: String, fallback: &str) -> Ident {
    let base = if base.is_empty() { fallback.to_string() } else { base };
    let mut name = base.clone();
    let mut k = 2;
    while !taken.insert(name.clone()) {
        name = format!("{base}_{k}");
        k += 1;
    }
    ident(&name)
}

/// `CaseStudy` -> `case_study`, `HTTPServer` -> `http_server`, `A` -> `a`.
pub fn snake_case(name: &str) -> String {
    let chars: Vec<char> = name.chars().collect();
    let mut out = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            let prev = chars[i - 1];
            let next_lower = chars.get(i + 1).is_some_and(|n| n.is_ascii_lowercase());
            if prev.is_ascii_lowercase()
                || prev.is_ascii_digit()
                || (prev.is_ascii_uppercase() && next_lower)
            {
                out.push('_');
            }
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// `go_home` -> `GoHome`, `a` -> `A`, `AB` -> `AB`.
pub fn camel_case(name: &str) -> String {
    let mut out = String::new();
    let mut upper = true;
    for c in name.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.push(c.to_ascii_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    if out.starts_with(|c: char| c.is_ascii_digit()) { format!("O{out}") } else { out }
}
