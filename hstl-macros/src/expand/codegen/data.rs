//! Formulas as data: the `hstl::robustness::Formula` builder code the monitors evaluate.

use super::*;

impl Gen<'_> {
    /// Statements adding `f` to the builder `__b` (the lets' nodes in `__l`), one node
    /// a statement: no nesting, however deep `f` is. Returns the variable of its node.
    pub(super) fn formula_data(&self, f: &CFormula, out: &mut Data) -> Ident {
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
    pub(super) fn build_lets(&self) -> TokenStream {
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
    pub(super) fn formula_expr(&self, f: &CFormula, lets: &TokenStream) -> TokenStream {
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
}

pub(super) fn interval_data(iv: &Interval, hstl: &TokenStream) -> TokenStream {
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
pub(super) struct Data {
    pub(super) stmts: Vec<TokenStream>,
    pub(super) vars: usize,
}

impl Data {
    /// A statement `let __n<k> = node;`; returns `__n<k>`.
    pub(super) fn push(&mut self, node: TokenStream) -> Ident {
        let v = format_ident!("__n{}", self.vars);
        self.vars += 1;
        self.stmts.push(quote!(let #v = #node;));
        v
    }

    pub(super) fn take(&mut self) -> Vec<TokenStream> {
        std::mem::take(&mut self.stmts)
    }

    /// Statements adding expression `e` to `__b`; returns the variable of its node.
    pub(super) fn expr(&mut self, e: &CExpr) -> Ident {
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
