//! The generated monitors: the lets module, each formula's offline and online monitor.

use super::body::Body;
use super::*;

impl Gen<'_> {
    /// The lets module: a monitor module per valid let, and what they share: `__build`
    /// (every let's node, each added once), `__sig_<i>` (let `i`'s signal given the
    /// signals of the lets it uses) and `__signals` (the signals a formula needs, each let
    /// computed once, in dependency order). The code is linear in the spec: a let's code
    /// names the lets it uses, never their bodies.
    pub(super) fn lets(&self) -> TokenStream {
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
    pub(super) fn monitor(
        &self,
        f: &CFormula,
        index: Option<usize>,
        lets: &TokenStream,
        state: &TokenStream,
        doc: &TokenStream,
        name: &TokenStream,
    ) -> TokenStream {
        let hstl = &self.root;
        let online = self.online(state);
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

                #online
            }
        }
    }

    /// The `Online` monitor of a formula module, the same for every formula: the runtime's
    /// streaming monitor over the module's `formula()`.
    fn online(&self, state: &TokenStream) -> TokenStream {
        let hstl = &self.root;
        quote! {
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

    /// The formula's horizon as the runtime computes it (`Formula::horizon`): the steps
    /// after `t` that `rho(f, t)` reads; `None` when unbounded (or past `usize`).
    pub(super) fn horizon(&self, f: &CFormula) -> Option<usize> {
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
    pub(super) fn empty_value(&self, f: &CFormula) -> f64 {
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
    /// The lets `f` names whose signals it reads (the leaf state lets are fused instead).
    pub(super) fn signal_deps(&self, f: &CFormula) -> Vec<usize> {
        let leaf = |i: usize| self.let_leaf.get(i).copied().unwrap_or(false);
        let_deps(f).into_iter().filter(|&i| !leaf(i)).collect()
    }
    /// The monitors of leaf state let `i`: its fused expression on each state.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn leaf_monitor(
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
        let online = self.online(state);
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

                #online
            }
        }
    }
}
