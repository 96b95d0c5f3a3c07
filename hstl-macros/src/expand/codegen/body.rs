//! The fused signal code of a formula: one `let` per operator over the kernels.

use super::data::interval_data;
use super::*;

/// Code for one formula's signal over `trace` (a `&[State]`), with the kernels `k` in
/// scope: one `let` statement per operator. State subformulas become one fused expression
/// per step, mapped over the trace; the temporal structure goes to the offline evaluator's
/// kernels (`hstl::robustness::kernels`), piece by piece where the horizon is finite, as
/// the evaluator itself runs it.
pub(super) struct Body<'g, 'a> {
    pub(super) g: &'g Gen<'a>,
    /// The path of the lets module (its `__at_<i>` functions).
    pub(super) lets: &'g TokenStream,
    /// The statements of the block being written (a closure body opens a new one).
    pub(super) stmts: Vec<TokenStream>,
    /// The number of `sig<n>` variables so far.
    pub(super) vars: usize,
    pub(super) uses_state: bool,
    pub(super) uses_kernels: bool,
}

/// A signal in generated code: a `let mut` variable, or an expression of type `Vec<f64>`.
pub(super) enum Sig {
    Var(Ident),
    Expr(TokenStream),
}

impl Sig {
    pub(super) fn tokens(&self) -> TokenStream {
        match self {
            Sig::Var(v) => quote!(#v),
            Sig::Expr(e) => e.clone(),
        }
    }
}

impl<'g, 'a> Body<'g, 'a> {
    pub(super) fn new(g: &'g Gen<'a>, lets: &'g TokenStream) -> Body<'g, 'a> {
        Body { g, lets, stmts: Vec::new(), vars: 0, uses_state: false, uses_kernels: false }
    }

    /// The statements and the final expression of the signal of `f`.
    pub(super) fn block(&mut self, f: &CFormula) -> TokenStream {
        let sig = self.signal(f, false).tokens();
        let stmts = std::mem::take(&mut self.stmts);
        quote!(#(#stmts)* #sig)
    }

    /// A `let mut` variable holding `sig`.
    pub(super) fn var(&mut self, sig: Sig) -> Ident {
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
    pub(super) fn signal(&mut self, f: &CFormula, in_piece: bool) -> Sig {
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
    pub(super) fn map(&mut self, fs: &[&CFormula], fold: Option<bool>) -> TokenStream {
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
    pub(super) fn operator(&mut self, f: &CFormula, in_piece: bool) -> Sig {
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
    pub(super) fn point(&mut self, f: &CFormula) -> TokenStream {
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

    pub(super) fn operand(&self, e: &CExpr) -> TokenStream {
        let x = self.expr(e);
        match e.kind {
            CExprKind::Const(c) if c >= 0.0 => x,
            _ => quote!((#x)),
        }
    }

    pub(super) fn expr(&self, e: &CExpr) -> TokenStream {
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
pub(super) fn fold_parts(parts: &[TokenStream], and: bool) -> TokenStream {
    if and {
        quote!(f64::INFINITY #(.min(#parts))*)
    } else {
        quote!(f64::NEG_INFINITY #(.max(#parts))*)
    }
}
