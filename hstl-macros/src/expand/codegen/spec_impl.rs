//! The implementation of the runtime's `Spec` trait.

use super::data::Data;
use super::*;

impl Gen<'_> {
    pub(super) fn spec_impl(&self, src: &str) -> TokenStream {
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
