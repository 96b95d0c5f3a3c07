//! Checked specs to Rust: a module per spec with its state type, options enums, monitors
//! and an implementation of the runtime's `Spec` trait.

use std::collections::HashSet;

use hstl_lang::{
    Bound, CExpr, CExprKind, CFormula, CFormulaKind, CheckedSpec, CmpOp, Domain, Interval, LetKind,
    Terminate, VarType,
};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

/// The generated module of one spec. `complete` says whether the spec checked without
/// errors; otherwise only the parts that checked are generated (no `Spec` implementation),
/// so an editor keeps completing inside a half-typed spec.
pub fn spec_module(spec: &CheckedSpec, src: &str, complete: bool) -> TokenStream {
    let g = Gen::new(spec);
    let module = ident(&snake_case(&spec.name));
    let doc = doc_attrs(spec.doc.as_deref());
    let state = g.state();
    let primitives = g.primitive_enum();
    let options = g.options_enum();
    let rt = runtime_helpers();
    let lets = g.lets();
    let task = match &spec.task {
        Some(t) if g.valid(&t.formula) => g.monitor(
            &t.formula,
            &quote!(super::lets),
            &quote!(super::State),
            &doc_or(t.doc.as_deref(), "The task: its robustness monitors."),
            &quote!(task),
        ),
        _ => TokenStream::new(),
    };
    let spec_impl = if complete { g.spec_impl(src) } else { TokenStream::new() };
    quote! {
        #doc
        #[allow(dead_code)]
        pub mod #module {
            #state
            #primitives
            #options
            #task
            /// The monitors of the spec's `let`s, one module each.
            pub mod lets {
                #lets
            }
            #spec_impl
            #rt
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
}

impl<'a> Gen<'a> {
    fn new(spec: &'a CheckedSpec) -> Gen<'a> {
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
        Gen { spec, let_names, prim_variants, option_variants }
    }

    /// Whether a formula (and every let it uses) checked.
    fn valid(&self, f: &CFormula) -> bool {
        let mut seen = HashSet::new();
        self.valid_in(f, &mut seen)
    }

    fn valid_in(&self, f: &CFormula, seen: &mut HashSet<usize>) -> bool {
        match &f.kind {
            CFormulaKind::Invalid => false,
            CFormulaKind::True | CFormulaKind::False => true,
            CFormulaKind::Let(i) => {
                if !seen.insert(*i) {
                    // A let met twice on one path is a cycle; one met on two paths is fine,
                    // but cycles are left out of `let_order`, so that decides.
                    return self.spec.let_order.contains(i);
                }
                let ok = self.spec.let_order.contains(i)
                    && self.spec.lets.get(*i).is_some_and(|l| self.valid_in(&l.formula, seen));
                seen.remove(i);
                ok
            }
            CFormulaKind::Cmp(_, a, b) => valid_expr(a) && valid_expr(b),
            CFormulaKind::Not(a) | CFormulaKind::Always(_, a) | CFormulaKind::Eventually(_, a) => {
                self.valid_in(a, seen)
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                !v.is_empty() && v.iter().all(|g| self.valid_in(g, seen))
            }
            CFormulaKind::Implies(a, b) | CFormulaKind::Until(_, a, b) => {
                self.valid_in(a, seen) && self.valid_in(b, seen)
            }
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
            VarType::Float => quote!(self.#f),
        });
        let from = vars.iter().zip(&fields).enumerate().map(|(i, (v, f))| match v.ty {
            VarType::Int => quote! { #f: int(*values.get(#i)?)?, },
            VarType::Float => quote! { #f: *values.get(#i)?, },
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

    fn lets(&self) -> TokenStream {
        self.spec
            .let_order
            .iter()
            .filter_map(|&i| {
                let l = self.spec.lets.get(i)?;
                if !self.valid(&l.formula) {
                    return None;
                }
                let doc = doc_or(l.doc.as_deref(), &format!("The `let` `{}`.", l.name));
                Some(self.monitor(
                    &l.formula,
                    &quote!(super),
                    &quote!(super::super::State),
                    &doc,
                    &{
                        let name = &self.let_names[i];
                        quote!(#name)
                    },
                ))
            })
            .collect()
    }

    /// A module of monitors for one formula. `lets` is the path of the lets module seen
    /// from inside it.
    fn monitor(
        &self,
        f: &CFormula,
        lets: &TokenStream,
        state: &TokenStream,
        doc: &TokenStream,
        name: &TokenStream,
    ) -> TokenStream {
        let data = self.formula_data(f, lets);
        // The helpers live in the spec module, one level above the task, two above a let.
        let rt =
            if lets.to_string() == "super" { quote!(super::super::rt) } else { quote!(super::rt) };
        let empty = lit_f64(self.empty_value(f, &mut Vec::new()));
        let mut body = Body {
            g: self,
            lets,
            rt: &rt,
            stmts: Vec::new(),
            uses_state: false,
            uses_t: false,
            n: 0,
        };
        let signal = body.signal(f);
        let stmts = &body.stmts;
        let at = if self.spec.is_state_formula(f) {
            let mut b = Body {
                g: self,
                lets,
                rt: &rt,
                stmts: Vec::new(),
                uses_state: false,
                uses_t: false,
                n: 0,
            };
            let p = b.point(f);
            let arg = if b.uses_state { quote!(s) } else { quote!(_s) };
            quote! {
                /// Robustness on one state (a state formula reads no other).
                pub fn at(#arg: &#state) -> f64 {
                    #p
                }
            }
        } else {
            TokenStream::new()
        };
        quote! {
            #doc
            pub mod #name {
                #at

                /// The formula as the runtime's data.
                pub fn formula() -> ::hstl::robustness::Formula {
                    #data
                }

                /// Robustness at every step of the trace.
                pub fn signal(trace: &[#state]) -> ::std::vec::Vec<f64> {
                    #(#stmts)*
                    #signal
                }

                /// Robustness of the trace: at step 0 (what the reference evaluator gives
                /// for an empty trace when it is empty).
                pub fn robustness(trace: &[#state]) -> f64 {
                    signal(trace).first().copied().unwrap_or(#empty)
                }

                /// Monitors the formula on states pushed one at a time (the runtime's
                /// streaming monitor over [`formula`]).
                #[derive(Clone, Debug)]
                pub struct Online {
                    monitor: ::hstl::robustness::OnlineMonitor,
                }

                impl Online {
                    /// A monitor at step 0.
                    pub fn new() -> Online {
                        Online { monitor: ::hstl::robustness::OnlineMonitor::new(&formula(), <#state>::VARS) }
                    }

                    /// Appends one state; returns the verdict it completes, if any.
                    pub fn push(&mut self, state: &#state) -> ::core::option::Option<::hstl::robustness::Verdict> {
                        // The row always has VARS values, so the monitor cannot refuse it.
                        self.monitor.push(&state.values()).ok().flatten()
                    }

                    /// The value the first open step would get if the trace ended now.
                    pub fn provisional(&mut self) -> ::core::option::Option<f64> {
                        self.monitor.provisional()
                    }

                    /// Ends the trace: the verdicts of every open step; the monitor then
                    /// starts a new trace.
                    pub fn finish(&mut self) -> ::std::vec::Vec<::hstl::robustness::Verdict> {
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

    /// The reference evaluator's `rho(f, 0)` on an empty trace.
    fn empty_value(&self, f: &CFormula, stack: &mut Vec<usize>) -> f64 {
        match &f.kind {
            CFormulaKind::True | CFormulaKind::Always(..) => f64::INFINITY,
            CFormulaKind::False | CFormulaKind::Eventually(..) | CFormulaKind::Until(..) => {
                f64::NEG_INFINITY
            }
            CFormulaKind::Cmp(..) | CFormulaKind::Invalid => f64::NAN,
            CFormulaKind::Let(i) => {
                if stack.contains(i) {
                    return f64::NAN;
                }
                stack.push(*i);
                let v = self
                    .spec
                    .lets
                    .get(*i)
                    .map_or(f64::NAN, |l| self.empty_value(&l.formula, stack));
                stack.pop();
                v
            }
            CFormulaKind::Not(a) => -self.empty_value(a, stack),
            CFormulaKind::And(v) => {
                v.iter().map(|g| self.empty_value(g, stack)).fold(f64::INFINITY, f64::min)
            }
            CFormulaKind::Or(v) => {
                v.iter().map(|g| self.empty_value(g, stack)).fold(f64::NEG_INFINITY, f64::max)
            }
            CFormulaKind::Implies(a, b) => {
                (-self.empty_value(a, stack)).max(self.empty_value(b, stack))
            }
        }
    }

    /// Code building the runtime's `Formula`; lets are calls to their `formula()`.
    fn formula_data(&self, f: &CFormula, lets: &TokenStream) -> TokenStream {
        let boxed = |g: &CFormula| {
            let d = self.formula_data(g, lets);
            quote!(::std::boxed::Box::new(#d))
        };
        match &f.kind {
            CFormulaKind::True => quote!(::hstl::robustness::Formula::True),
            CFormulaKind::False | CFormulaKind::Invalid => {
                quote!(::hstl::robustness::Formula::False)
            }
            CFormulaKind::Let(i) => {
                let name = &self.let_names[*i];
                quote!(#lets::#name::formula())
            }
            CFormulaKind::Cmp(op, a, b) => {
                let op = match op {
                    CmpOp::Lt => quote!(Lt),
                    CmpOp::Le => quote!(Le),
                    CmpOp::Gt => quote!(Gt),
                    CmpOp::Ge => quote!(Ge),
                };
                let (a, b) = (expr_data(a), expr_data(b));
                quote!(::hstl::robustness::Formula::Cmp { lhs: #a, op: ::hstl::robustness::CmpOp::#op, rhs: #b })
            }
            CFormulaKind::Not(a) => {
                let a = boxed(a);
                quote!(::hstl::robustness::Formula::Not(#a))
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                let parts = v.iter().map(|g| self.formula_data(g, lets));
                let kind =
                    if matches!(f.kind, CFormulaKind::And(_)) { quote!(And) } else { quote!(Or) };
                quote!(::hstl::robustness::Formula::#kind(::std::vec![#(#parts),*]))
            }
            CFormulaKind::Implies(a, b) => {
                let (a, b) = (boxed(a), boxed(b));
                quote!(::hstl::robustness::Formula::Implies(#a, #b))
            }
            CFormulaKind::Always(iv, a) | CFormulaKind::Eventually(iv, a) => {
                let kind = if matches!(f.kind, CFormulaKind::Always(..)) {
                    quote!(Always)
                } else {
                    quote!(Eventually)
                };
                let (iv, a) = (interval_data(iv), boxed(a));
                quote!(::hstl::robustness::Formula::#kind(#iv, #a))
            }
            CFormulaKind::Until(iv, a, b) => {
                let (iv, a, b) = (interval_data(iv), boxed(a), boxed(b));
                quote!(::hstl::robustness::Formula::Until(#iv, #a, #b))
            }
        }
    }

    fn spec_impl(&self, src: &str) -> TokenStream {
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
        let lets = quote!(lets);
        let vars = self.spec.state_vars.iter().map(|v| {
            let name = &v.name;
            let domain = match v.domain {
                Domain::Int { lo, hi } => quote!(::core::option::Option::Some(#lo..=#hi)),
                _ => quote!(::core::option::Option::None),
            };
            quote!(::hstl::runtime::StateVar { name: ::std::string::String::from(#name), domain: #domain })
        });
        let prims = self.spec.primitives.iter().map(|p| {
            let name = &p.name;
            let reach = self.formula_data(&p.reach, &lets);
            let init = self.formula_data(&p.init, &lets);
            let terminate = match &p.terminate {
                Terminate::Argmax => quote!(::hstl::runtime::Terminate::Argmax),
                Terminate::Formula(f) => {
                    let f = self.formula_data(f, &lets);
                    quote!(::hstl::runtime::Terminate::Formula(#f))
                }
            };
            quote! {
                ::hstl::runtime::PrimitiveOption {
                    name: ::std::string::String::from(#name),
                    reach: #reach,
                    init: #init,
                    terminate: #terminate,
                }
            }
        });
        let options = self.spec.options.iter().map(|o| {
            let name = &o.name;
            let seq = &o.sequence;
            quote! {
                ::hstl::runtime::CombinedOption {
                    name: ::std::string::String::from(#name),
                    sequence: ::std::vec![#(#seq),*],
                }
            }
        });
        let regions =
            self.spec.persistent_conjuncts(src).unwrap_or_default().into_iter().map(|c| {
                let name = c.name;
                let formula = self.formula_data(&c.region, &lets);
                let steps = Literal::u64_unsuffixed(c.steps);
                quote! {
                    ::hstl::runtime::Region {
                        name: ::std::string::String::from(#name),
                        formula: #formula,
                        horizon: #steps,
                    }
                }
            });
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
                ::hstl::runtime::LevelParams { gamma: #g, alpha: #a, epsilon: #e, min_epsilon: #m, decay: #d }
            }
        };
        let (flat, opts) = (level(&l.flat), level(&l.options));
        let (episodes, choices, max_steps, memory) = (
            Literal::u64_unsuffixed(l.episodes),
            Literal::u64_unsuffixed(l.choices),
            Literal::u64_unsuffixed(l.max_steps),
            Literal::u64_unsuffixed(l.memory),
        );
        let intra = match l.intra {
            hstl_lang::Intra::Paper => quote!(Paper),
            hstl_lang::Intra::Remaining => quote!(Remaining),
        };
        let reward = match l.reward {
            hstl_lang::Reward::Segment => quote!(Segment),
            hstl_lang::Reward::Window => quote!(Window),
        };
        let doc =
            format!(" The spec `{name}` for the runtime: train it with `hstl::runtime::Learner`.");
        quote! {
            #[doc = #doc]
            #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
            pub struct #ty;

            impl #ty {
                /// The spec as the runtime's plain data.
                pub fn task_spec() -> ::hstl::runtime::TaskSpec {
                    ::hstl::runtime::TaskSpec {
                        name: ::std::string::String::from(#name),
                        state_vars: ::std::vec![#(#vars),*],
                        task: task::formula(),
                        primitives: ::std::vec![#(#prims),*],
                        options: ::std::vec![#(#options),*],
                        learn: ::hstl::runtime::LearnParams {
                            episodes: #episodes,
                            choices: #choices,
                            max_steps: #max_steps,
                            memory: #memory,
                            intra: ::hstl::runtime::Intra::#intra,
                            reward: ::hstl::runtime::RewardKind::#reward,
                            flat: #flat,
                            options: #opts,
                        },
                        regions: ::std::vec![#(#regions),*],
                    }
                }
            }

            impl ::hstl::runtime::Spec for #ty {
                fn task_spec(&self) -> ::hstl::runtime::TaskSpec {
                    #ty::task_spec()
                }
            }
        }
    }
}

/// Straight-line code for one formula's signal: temporal operators become statements
/// over whole signals, everything else an expression at step `t` on state `s`.
struct Body<'g, 'a> {
    g: &'g Gen<'a>,
    lets: &'g TokenStream,
    rt: &'g TokenStream,
    stmts: Vec<TokenStream>,
    uses_state: bool,
    uses_t: bool,
    n: usize,
}

impl Body<'_, '_> {
    /// An expression of type `Vec<f64>`: the signal of `f` (`n` is the trace length).
    fn signal(&mut self, f: &CFormula) -> TokenStream {
        match &f.kind {
            CFormulaKind::Let(i)
                if self.g.spec.lets.get(*i).is_some_and(|l| l.kind == LetKind::Temporal) =>
            {
                let lets = self.lets;
                let name = &self.g.let_names[*i];
                quote!(#lets::#name::signal(trace))
            }
            CFormulaKind::Always(..) | CFormulaKind::Eventually(..) | CFormulaKind::Until(..) => {
                self.temporal(f)
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v)
                if !v.is_empty() && v.iter().all(|g| self.is_vector(g)) =>
            {
                // Fold whole signals in place rather than indexing each at every step.
                let (neutral, op) = if matches!(f.kind, CFormulaKind::And(_)) {
                    (quote!(f64::INFINITY), quote!(min))
                } else {
                    (quote!(f64::NEG_INFINITY), quote!(max))
                };
                let acc = format_ident!("sig{}", self.n);
                self.n += 1;
                let first = self.signal(&v[0]);
                self.stmts.push(quote! {
                    let mut #acc: ::std::vec::Vec<f64> = #first;
                    for x in #acc.iter_mut() {
                        *x = #neutral.#op(*x);
                    }
                });
                for g in &v[1..] {
                    let c = self.signal(g);
                    self.stmts.push(quote! {
                        for (x, y) in #acc.iter_mut().zip(#c) {
                            *x = x.#op(y);
                        }
                    });
                }
                quote!(#acc)
            }
            _ => {
                let before = (self.uses_state, self.uses_t);
                (self.uses_state, self.uses_t) = (false, false);
                let p = self.point(f);
                let used = (self.uses_state, self.uses_t);
                (self.uses_state, self.uses_t) = before;
                let map = match used {
                    (true, true) => quote!(trace.iter().enumerate().map(|(t, s)| #p)),
                    (true, false) => quote!(trace.iter().map(|s| #p)),
                    (false, true) => quote!((0..trace.len()).map(|t| #p)),
                    (false, false) => quote!(trace.iter().map(|_| #p)),
                };
                quote!(#map.collect::<::std::vec::Vec<f64>>())
            }
        }
    }

    /// Whether `f`'s signal is computed as a whole vector (not step by step).
    fn is_vector(&self, f: &CFormula) -> bool {
        match &f.kind {
            CFormulaKind::Always(..) | CFormulaKind::Eventually(..) | CFormulaKind::Until(..) => {
                true
            }
            CFormulaKind::Let(i) => {
                self.g.spec.lets.get(*i).is_some_and(|l| l.kind == LetKind::Temporal)
            }
            _ => false,
        }
    }

    /// A temporal operator: a statement computing its signal; returns the variable.
    fn temporal(&mut self, f: &CFormula) -> TokenStream {
        let v = format_ident!("sig{}", self.n);
        self.n += 1;
        let value = match &f.kind {
            CFormulaKind::Always(iv, a) => {
                let a = self.signal(a);
                let (s, e) = bounds(iv);
                {
                    let rt = self.rt;
                    quote!(#rt::window_min(#a, #s, #e))
                }
            }
            CFormulaKind::Eventually(iv, a) => {
                let a = self.signal(a);
                let (s, e) = bounds(iv);
                {
                    let rt = self.rt;
                    quote!(#rt::window_max(#a, #s, #e))
                }
            }
            CFormulaKind::Until(iv, a, b) => {
                let a = self.signal(a);
                let b = self.signal(b);
                let (s, e) = bounds(iv);
                {
                    let rt = self.rt;
                    quote!(#rt::until(&#a, &#b, #s, #e))
                }
            }
            _ => self.signal(f),
        };
        self.stmts.push(quote!(let #v: ::std::vec::Vec<f64> = #value;));
        quote!(#v)
    }

    /// An `f64` expression: `rho(f, t)`, reading the state `s = &trace[t]`.
    fn point(&mut self, f: &CFormula) -> TokenStream {
        match &f.kind {
            CFormulaKind::True => quote!(f64::INFINITY),
            CFormulaKind::False | CFormulaKind::Invalid => quote!(f64::NEG_INFINITY),
            CFormulaKind::Let(i) => {
                let lets = self.lets;
                let name = &self.g.let_names[*i];
                if self.g.spec.lets.get(*i).is_some_and(|l| l.kind == LetKind::State) {
                    self.uses_state = true;
                    quote!(#lets::#name::at(s))
                } else {
                    let v = format_ident!("sig{}", self.n);
                    self.n += 1;
                    self.stmts
                        .push(quote!(let #v: ::std::vec::Vec<f64> = #lets::#name::signal(trace);));
                    self.uses_t = true;
                    quote!(#v[t])
                }
            }
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
            CFormulaKind::And(v) => {
                let parts: Vec<TokenStream> = v.iter().map(|g| self.point(g)).collect();
                quote!(f64::INFINITY #(.min(#parts))*)
            }
            CFormulaKind::Or(v) => {
                let parts: Vec<TokenStream> = v.iter().map(|g| self.point(g)).collect();
                quote!(f64::NEG_INFINITY #(.max(#parts))*)
            }
            CFormulaKind::Implies(a, b) => {
                let (a, b) = (self.point(a), self.point(b));
                quote!((-(#a)).max(#b))
            }
            CFormulaKind::Always(..) | CFormulaKind::Eventually(..) | CFormulaKind::Until(..) => {
                let v = self.temporal(f);
                self.uses_t = true;
                quote!(#v[t])
            }
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
                        VarType::Float => quote!(s.#f),
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

/// The sliding-window and until helpers the monitors call. They follow the reference
/// evaluator's NaN policy (min and max skip NaN) by reading NaN as the neutral element.
fn runtime_helpers() -> TokenStream {
    quote! {
        mod rt {
            /// `min` of `sig` over the window `[t + start, t + end)` clipped to the trace,
            /// for every `t`; `+inf` when empty.
            pub(super) fn window_min(sig: ::std::vec::Vec<f64>, start: usize, end: usize) -> ::std::vec::Vec<f64> {
                if sig.iter().any(|x| x.is_nan()) {
                    window(sig, start, end, f64::INFINITY, f64::min)
                } else {
                    window(sig, start, end, f64::INFINITY, |a: f64, b: f64| if b < a { b } else { a })
                }
            }

            /// `max` of `sig` over the window `[t + start, t + end)` clipped to the trace,
            /// for every `t`; `-inf` when empty.
            pub(super) fn window_max(sig: ::std::vec::Vec<f64>, start: usize, end: usize) -> ::std::vec::Vec<f64> {
                if sig.iter().any(|x| x.is_nan()) {
                    window(sig, start, end, f64::NEG_INFINITY, f64::max)
                } else {
                    window(sig, start, end, f64::NEG_INFINITY, |a: f64, b: f64| if b > a { b } else { a })
                }
            }

            /// Folds every block of `w` steps of `buf` in place from the block's start
            /// (prefix folds); four blocks at a time so the folds overlap.
            #[inline(always)]
            fn scan<F: Fn(f64, f64) -> f64 + Copy>(buf: &mut [f64], w: usize, neutral: f64, op: F) {
                let n = buf.len();
                let groups = n / w / 4;
                for gi in 0..groups {
                    let base = gi * 4 * w;
                    let mut acc = [neutral; 4];
                    for j in 0..w {
                        for (k, a) in acc.iter_mut().enumerate() {
                            let u = base + k * w + j;
                            *a = op(*a, buf[u]);
                            buf[u] = *a;
                        }
                    }
                }
                let mut b = groups * 4 * w;
                while b < n {
                    let e = (b + w).min(n);
                    let mut acc = neutral;
                    for x in &mut buf[b..e] {
                        acc = op(acc, *x);
                        *x = acc;
                    }
                    b = e;
                }
            }

            /// `dst[u]`: the fold of `src` from `u` to the end of its block of `w` steps; four
            /// blocks at a time so the folds overlap.
            #[inline(always)]
            fn suffix_folds<F: Fn(f64, f64) -> f64 + Copy>(src: &[f64], dst: &mut [f64], w: usize, neutral: f64, op: F) {
                let n = src.len().min(dst.len());
                let groups = n / w / 4;
                for gi in 0..groups {
                    let base = gi * 4 * w;
                    let mut acc = [neutral; 4];
                    for j in (0..w).rev() {
                        for (k, a) in acc.iter_mut().enumerate() {
                            let u = base + k * w + j;
                            *a = op(*a, src[u]);
                            dst[u] = *a;
                        }
                    }
                }
                let mut b = groups * 4 * w;
                while b < n {
                    let e = (b + w).min(n);
                    let mut acc = neutral;
                    for u in (b..e).rev() {
                        acc = op(acc, src[u]);
                        dst[u] = acc;
                    }
                    b = e;
                }
            }

            /// Sliding windows by van Herk / Gil-Werman: per-block prefix and suffix folds,
            /// a few passes whatever the width, reusing the input as the prefix buffer.
            /// Folding from `neutral` with `f64::min` or `f64::max` skips NaN as the
            /// reference evaluator does.
            #[inline(always)]
            fn window<F: Fn(f64, f64) -> f64 + Copy>(
                mut sig: ::std::vec::Vec<f64>,
                start: usize,
                end: usize,
                neutral: f64,
                op: F,
            ) -> ::std::vec::Vec<f64> {
                let n = sig.len();
                if end <= start {
                    sig.fill(neutral);
                    return sig;
                }
                let w = end - start;
                if w >= n {
                    // Every window runs to the end: suffix folds, shifted by `start`.
                    let mut acc = neutral;
                    for x in sig.iter_mut().rev() {
                        acc = op(acc, *x);
                        *x = acc;
                    }
                    for t in 0..n {
                        sig[t] = match t.checked_add(start) {
                            ::core::option::Option::Some(l) if l < n => sig[l],
                            _ => neutral,
                        };
                    }
                    return sig;
                }
                // tail[k]: the fold over n - w + k .. n, for the windows the trace clips.
                let mut tail = ::std::vec![neutral; w + 1];
                for k in (0..w).rev() {
                    tail[k] = op(tail[k + 1], sig[n - w + k]);
                }
                // suf[u]: the fold from u to the end of its block; sig becomes the prefix
                // folds from the start of each block.
                let mut suf = ::std::vec![neutral; n];
                suffix_folds(&sig, &mut suf, w, neutral, op);
                scan(&mut sig, w, neutral, op);
                // Step t reads suf at t + start >= t, so the result can overwrite suf. Steps
                // before `full` see whole windows; the rest are clipped by the trace's end.
                let full = (n - w + 1).saturating_sub(start);
                if start == 0 {
                    for (x, y) in suf[..full].iter_mut().zip(&sig[w - 1..]) {
                        *x = op(*x, *y);
                    }
                } else {
                    for t in 0..full {
                        suf[t] = op(suf[t + start], sig[t + start + w - 1]);
                    }
                }
                for t in full..n {
                    let l = t.saturating_add(start);
                    suf[t] = if l >= n { neutral } else { tail[l + w - n] };
                }
                suf
            }

            /// `f until[start..end) g` at every step.
            pub(super) fn until(f: &[f64], g: &[f64], start: usize, end: usize) -> ::std::vec::Vec<f64> {
                let n = f.len().min(g.len());
                let mut out = ::std::vec![f64::NEG_INFINITY; n];
                if end <= start {
                    return out;
                }
                // A NaN operand is skipped by min, as in the reference evaluator.
                let fv = |u: usize| f64::INFINITY.min(f[u]);
                let gv = |u: usize| f64::INFINITY.min(g[u]);
                if end == usize::MAX {
                    // v[u]: the best over u' >= u of min(g(u'), min f over [u, u')).
                    let mut v = ::std::vec![f64::NEG_INFINITY; n + 1];
                    for u in (0..n).rev() {
                        v[u] = gv(u).max(fv(u).min(v[u + 1]));
                    }
                    let before = window_min(f[..n].to_vec(), 0, start);
                    for (t, o) in out.iter_mut().enumerate() {
                        let u = t.saturating_add(start);
                        if u < n {
                            *o = before[t].min(v[u]);
                        }
                    }
                } else {
                    for (t, o) in out.iter_mut().enumerate() {
                        let mut best = f64::NEG_INFINITY;
                        let mut run = f64::INFINITY;
                        for u in t..t.saturating_add(end).min(n) {
                            if u >= t + start {
                                best = best.max(gv(u).min(run));
                            }
                            run = run.min(fv(u));
                        }
                        *o = best;
                    }
                }
                out
            }
        }
    }
}

/// `(start, end)` offsets of an interval, `end` exclusive and `usize::MAX` when unbounded.
fn bounds(iv: &Interval) -> (TokenStream, TokenStream) {
    let start = Literal::usize_unsuffixed(usize::try_from(iv.start).unwrap_or(usize::MAX));
    let end = match iv.end {
        Bound::Unbounded => quote!(usize::MAX),
        Bound::Exclusive(b) => {
            let b = Literal::usize_unsuffixed(usize::try_from(b).unwrap_or(usize::MAX - 1));
            quote!(#b)
        }
        Bound::Inclusive(b) => {
            let b =
                usize::try_from(b).unwrap_or(usize::MAX - 1).saturating_add(1).min(usize::MAX - 1);
            let b = Literal::usize_unsuffixed(b);
            quote!(#b)
        }
    };
    (quote!(#start), end)
}

fn interval_data(iv: &Interval) -> TokenStream {
    let start = Literal::u64_unsuffixed(iv.start);
    let end = match iv.end {
        Bound::Unbounded => quote!(::hstl::robustness::Bound::Unbounded),
        Bound::Exclusive(b) => {
            let b = Literal::u64_unsuffixed(b);
            quote!(::hstl::robustness::Bound::Exclusive(#b))
        }
        Bound::Inclusive(b) => {
            let b = Literal::u64_unsuffixed(b);
            quote!(::hstl::robustness::Bound::Inclusive(#b))
        }
    };
    quote!(::hstl::robustness::Interval { start: #start, end: #end })
}

fn expr_data(e: &CExpr) -> TokenStream {
    let boxed = |a: &CExpr| {
        let d = expr_data(a);
        quote!(::std::boxed::Box::new(#d))
    };
    match &e.kind {
        CExprKind::Const(c) => {
            let c = lit_f64(*c);
            quote!(::hstl::robustness::Expr::Const(#c))
        }
        CExprKind::Invalid => quote!(::hstl::robustness::Expr::Const(f64::NAN)),
        CExprKind::Var(i) => quote!(::hstl::robustness::Expr::Var(#i)),
        CExprKind::Neg(a) | CExprKind::Abs(a) | CExprKind::Sqrt(a) => {
            let kind = match e.kind {
                CExprKind::Neg(_) => quote!(Neg),
                CExprKind::Abs(_) => quote!(Abs),
                _ => quote!(Sqrt),
            };
            let a = boxed(a);
            quote!(::hstl::robustness::Expr::#kind(#a))
        }
        CExprKind::Add(a, b)
        | CExprKind::Sub(a, b)
        | CExprKind::Mul(a, b)
        | CExprKind::Div(a, b) => {
            let kind = match e.kind {
                CExprKind::Add(..) => quote!(Add),
                CExprKind::Sub(..) => quote!(Sub),
                CExprKind::Mul(..) => quote!(Mul),
                _ => quote!(Div),
            };
            let (a, b) = (boxed(a), boxed(b));
            quote!(::hstl::robustness::Expr::#kind(#a, #b))
        }
    }
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
        VarType::Float => quote!(f64),
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
