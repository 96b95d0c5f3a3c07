//! The generated types: the state struct and the options enums.

use super::*;

impl Gen<'_> {
    pub(super) fn state(&self) -> TokenStream {
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
    pub(super) fn primitive_enum(&self) -> TokenStream {
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
    pub(super) fn options_enum(&self) -> TokenStream {
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
}
