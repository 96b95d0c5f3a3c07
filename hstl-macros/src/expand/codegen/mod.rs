//! Checked specs to Rust: a module per spec with its state type, options enums, monitors
//! and an implementation of the runtime's `Spec` trait.

use std::collections::HashSet;

use hstl_lang::{
    Bound, CExpr, CExprKind, CFormula, CFormulaKind, CheckedSpec, CmpOp, Domain, Interval,
    Terminate, VarType,
};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

mod body;
mod data;
mod monitor;
mod names;
mod spec_impl;
mod types;

use names::unique;
pub use names::{camel_case, ident, snake_case};

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
            CFormulaKind::Let(i) => self.let_valid.get(*i).copied().unwrap_or(false),
            CFormulaKind::Cmp(_, a, b) => valid_expr(a) && valid_expr(b),
            CFormulaKind::And(v) | CFormulaKind::Or(v) if v.is_empty() => false,
            // `true` and `false` have no operands: valid.
            _ => f.operands().into_iter().all(|g| self.valid(g)),
        }
    }
}

/// Whether `f` has a past-time operator (not looking through lets, whose signals are
/// computed over the whole trace). The walk keeps its own stack.
fn has_past_node(f: &CFormula) -> bool {
    let mut stack = vec![f];
    while let Some(f) = stack.pop() {
        if matches!(
            f.kind,
            CFormulaKind::Once(..)
                | CFormulaKind::Historically(..)
                | CFormulaKind::Since(..)
                | CFormulaKind::Prev(..)
        ) {
            return true;
        }
        stack.extend(f.operands());
    }
    false
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
