//! Shared test helpers: a small parser for hstl formulas, and one check that runs every
//! evaluator against expected values.
#![allow(dead_code)]

use hstl_robustness::{
    Bound, CmpOp, Evaluator, Expr, Formula, Interval, OnlineMonitor, Trace, offline, reference,
    segment::{SegmentScorer, TabularScorer},
};

/// The state variables of the test traces, in column order.
pub const VARS: [&str; 2] = ["x", "y"];

/// Whether two robustness values are the same: equal (so `0 == -0`), or both NaN.
pub fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

/// Asserts that two signals are the same value for value.
pub fn assert_same(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (t, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(same(*g, *w), "{what}: step {t}: got {g}, want {w}\n got  {got:?}\n want {want:?}");
    }
}

/// Checks every evaluator against `want` (the signal) on `trace`: the reference, the
/// offline signal, the step-0 robustness (on every suffix), the online monitor, and the
/// segment scorers against the reference segment reward of every suffix.
pub fn check_all(f: &Formula, trace: &Trace, want: &[f64]) {
    // A shared formula written out can be exponentially long: large ones go by size.
    let label = if f.tree_len() < 10_000 {
        format!("{}", f.display_with(&VARS))
    } else {
        format!("a formula of {} nodes", f.len())
    };
    assert_same(&format!("reference {label}"), &reference::signal(f, trace), want);
    assert_same(&format!("offline {label}"), &offline::signal(f, trace), want);
    let mut ev = Evaluator::new();
    // Twice through one evaluator: reused buffers must not leak between calls.
    for _ in 0..2 {
        assert_same(&format!("evaluator {label}"), ev.signal(f, trace), want);
    }
    let r0 = ev.robustness(f, trace);
    assert!(same(r0, reference::robustness(f, trace, 0)), "{label}: step 0 gave {r0}");
    for (i, w) in want.iter().enumerate() {
        // A past-time operator reads the steps before `i`: a suffix does not give `rho(f, i)`.
        let r = if f.has_past() {
            reference::robustness(f, trace, i)
        } else {
            ev.robustness(f, &suffix(trace, i))
        };
        assert!(same(r, *w), "{label}: step 0 of suffix {i} gave {r}, want {w}");
    }
    if !trace.is_empty() {
        assert!(same(r0, want[0]), "{label}: step 0 gave {r0}, want {}", want[0]);
    }
    check_online(f, trace, want, &label);
    check_segments(f, trace, &label);
}

fn check_online(f: &Formula, trace: &Trace, want: &[f64], label: &str) {
    let mut m = OnlineMonitor::new(f, trace.vars());
    let mut got = Vec::new();
    let mut row = Vec::new();
    let mut prefix = Trace::new(trace.vars());
    for t in 0..trace.len() {
        trace.row_into(t, &mut row);
        let v = m.push(&row).expect("rows have the trace's width");
        match (f.horizon(), v) {
            (Some(h), Some(v)) => {
                assert_eq!(Some(v.step), t.checked_sub(h), "{label}: verdict step");
                got.push(v);
            }
            (Some(h), None) => assert!(t < h, "{label}: no verdict at step {t}"),
            (None, v) => assert_eq!(v, None, "{label}: verdict before the end"),
        }
        // The open steps as if the trace ended here: the prefix's signal at those steps.
        prefix.push(&row).expect("rows have the trace's width");
        let open = m.open_values();
        let whole = offline::signal(f, &prefix);
        assert_same(&format!("open steps after {t} of {label}"), &open, &whole[got.len()..]);
    }
    got.extend(m.finish());
    let steps: Vec<usize> = got.iter().map(|v| v.step).collect();
    assert_eq!(steps, (0..trace.len()).collect::<Vec<_>>(), "{label}: online steps");
    let values: Vec<f64> = got.iter().map(|v| v.value).collect();
    assert_same(&format!("online {label}"), &values, want);
}

fn check_segments(f: &Formula, trace: &Trace, label: &str) {
    let n = trace.len();
    let want: Vec<f64> = (0..n).map(|i| reference::segment_reward(f, &suffix(trace, i))).collect();
    let mut scorer = SegmentScorer::new(f);
    let mut got = Vec::new();
    scorer.suffix_rewards(trace, &mut got);
    assert_same(&format!("suffix rewards {label}"), &got, &want);
    let r = scorer.reward(trace);
    assert!(same(r, reference::segment_reward(f, trace)), "{label}: segment reward {r}");
    // The trace's rows double as the state table; the segment visits them in order.
    let mut tab = TabularScorer::new(f, trace);
    let idx: Vec<usize> = (0..n).collect();
    tab.suffix_rewards(&idx, &mut got);
    assert_same(&format!("tabular suffix rewards {label}"), &got, &want);
    let r = tab.reward(&idx);
    assert!(same(r, reference::segment_reward(f, trace)), "{label}: tabular reward {r}");
}

/// The steps `i..` of `trace`.
pub fn suffix(trace: &Trace, i: usize) -> Trace {
    let cols = (0..trace.vars()).map(|c| trace.column(c)[i..].to_vec()).collect();
    Trace::from_columns(cols).expect("columns of one trace")
}

/// A trace over `x` and `y`.
pub fn trace_xy(x: &[f64], y: &[f64]) -> Trace {
    Trace::from_columns(vec![x.to_vec(), y.to_vec()]).expect("equal lengths")
}

/// Parses a formula in hstl syntax over the variables [`VARS`] (no `let` names).
pub fn parse(src: &str) -> Formula {
    let mut p = Parser { toks: lex(src), pos: 0 };
    let f = p.formula();
    assert_eq!(p.pos, p.toks.len(), "trailing input in {src:?}: {:?}", &p.toks[p.pos..]);
    f
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Ident(String),
    Sym(&'static str),
}

fn lex(src: &str) -> Vec<Tok> {
    const SYMS: [&str; 20] = [
        "..=", "->", "&&", "||", "<=", ">=", "..", "<", ">", "!", "(", ")", "[", "]", "+", "-",
        "*", "/", ",", ";",
    ];
    let mut out = Vec::new();
    let b = src.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let c = b[i] as char;
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() {
            let start = i;
            while i < b.len()
                && (b[i].is_ascii_digit() || b[i] == b'.' && b.get(i + 1) != Some(&b'.'))
            {
                i += 1;
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                i += 1;
                if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
                    i += 1;
                }
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
            out.push(Tok::Num(src[start..i].parse().expect("a number")));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push(Tok::Ident(src[start..i].to_string()));
        } else {
            let s = SYMS.iter().find(|s| src[i..].starts_with(**s)).expect("a known symbol");
            out.push(Tok::Sym(s));
            i += s.len();
        }
    }
    out
}

struct Parser {
    toks: Vec<Tok>,
    pos: usize,
}

impl Parser {
    fn peek_sym(&self, s: &str) -> bool {
        matches!(self.toks.get(self.pos), Some(Tok::Sym(t)) if *t == s)
    }

    fn peek_ident(&self, s: &str) -> bool {
        matches!(self.toks.get(self.pos), Some(Tok::Ident(t)) if t == s)
    }

    fn eat_sym(&mut self, s: &str) -> bool {
        let hit = self.peek_sym(s);
        self.pos += usize::from(hit);
        hit
    }

    fn expect_sym(&mut self, s: &str) {
        assert!(
            self.eat_sym(s),
            "expected {s} at token {}: {:?}",
            self.pos,
            self.toks.get(self.pos)
        );
    }

    fn formula(&mut self) -> Formula {
        let lhs = self.or();
        if self.eat_sym("->") { Formula::implies(lhs, self.formula()) } else { lhs }
    }

    fn or(&mut self) -> Formula {
        let mut fs = vec![self.and()];
        while self.eat_sym("||") {
            fs.push(self.and());
        }
        if fs.len() == 1 { fs.pop().expect("one") } else { Formula::or(fs) }
    }

    fn and(&mut self) -> Formula {
        let mut fs = vec![self.until()];
        while self.eat_sym("&&") {
            fs.push(self.until());
        }
        if fs.len() == 1 { fs.pop().expect("one") } else { Formula::and(fs) }
    }

    fn until(&mut self) -> Formula {
        let lhs = self.unary();
        for kw in ["until", "since"] {
            if self.peek_ident(kw) {
                self.pos += 1;
                let i = self.interval();
                let rhs = self.unary();
                return if kw == "until" {
                    Formula::until(i, lhs, rhs)
                } else {
                    Formula::since(i, lhs, rhs)
                };
            }
        }
        lhs
    }

    fn unary(&mut self) -> Formula {
        if self.eat_sym("!") {
            return Formula::not(self.unary());
        }
        for kw in ["always", "eventually", "once", "historically"] {
            if self.peek_ident(kw) {
                self.pos += 1;
                let i = self.interval();
                let f = self.unary();
                return match kw {
                    "always" => Formula::always(i, f),
                    "eventually" => Formula::eventually(i, f),
                    "once" => Formula::once(i, f),
                    _ => Formula::historically(i, f),
                };
            }
        }
        for kw in ["prev", "next"] {
            if self.peek_ident(kw) {
                self.pos += 1;
                let f = self.unary();
                return if kw == "prev" { Formula::prev(f) } else { Formula::next(f) };
            }
        }
        self.atom()
    }

    fn atom(&mut self) -> Formula {
        if self.peek_ident("true") || self.peek_ident("false") {
            self.pos += 1;
            return if self.toks[self.pos - 1] == Tok::Ident("true".into()) {
                Formula::bool(true)
            } else {
                Formula::bool(false)
            };
        }
        // A comparison is tried first, as the grammar says.
        let save = self.pos;
        if let Some(c) = self.try_comparison() {
            return c;
        }
        self.pos = save;
        self.expect_sym("(");
        let f = self.formula();
        self.expect_sym(")");
        f
    }

    fn try_comparison(&mut self) -> Option<Formula> {
        let mut lhs = self.try_expr()?;
        let mut parts = Vec::new();
        while let Some(op) = self.cmp_op() {
            let rhs = self.try_expr()?;
            parts.push(Formula::cmp(lhs.clone(), op, rhs.clone()));
            lhs = rhs;
        }
        match parts.len() {
            0 => None,
            1 => parts.pop(),
            _ => Some(Formula::and(parts)),
        }
    }

    fn cmp_op(&mut self) -> Option<CmpOp> {
        let op = [("<=", CmpOp::Le), (">=", CmpOp::Ge), ("<", CmpOp::Lt), (">", CmpOp::Gt)]
            .into_iter()
            .find(|(s, _)| self.peek_sym(s))?;
        self.pos += 1;
        Some(op.1)
    }

    fn try_expr(&mut self) -> Option<Expr> {
        let mut e = self.try_term()?;
        loop {
            if self.eat_sym("+") {
                e = Expr::add(e, self.try_term()?);
            } else if self.eat_sym("-") {
                e = Expr::sub(e, self.try_term()?);
            } else {
                return Some(e);
            }
        }
    }

    fn try_term(&mut self) -> Option<Expr> {
        let mut e = self.try_factor()?;
        loop {
            if self.eat_sym("*") {
                e = Expr::mul(e, self.try_factor()?);
            } else if self.eat_sym("/") {
                e = Expr::div(e, self.try_factor()?);
            } else {
                return Some(e);
            }
        }
    }

    fn try_factor(&mut self) -> Option<Expr> {
        if self.eat_sym("-") {
            return Some(Expr::neg(self.try_factor()?));
        }
        if self.eat_sym("(") {
            let e = self.try_expr()?;
            return self.eat_sym(")").then_some(e);
        }
        match self.toks.get(self.pos).cloned()? {
            Tok::Num(v) => {
                self.pos += 1;
                Some(Expr::constant(v))
            }
            Tok::Ident(name) if name == "abs" || name == "sqrt" => {
                self.pos += 1;
                if !self.eat_sym("(") {
                    return None;
                }
                let e = self.try_expr()?;
                self.eat_sym(")").then_some(())?;
                Some(if name == "abs" { Expr::abs(e) } else { Expr::sqrt(e) })
            }
            Tok::Ident(name) => {
                let i = VARS
                    .iter()
                    .position(|v| *v == name)
                    .or_else(|| name.strip_prefix('v').and_then(|d| d.parse().ok()))?;
                self.pos += 1;
                Some(Expr::var(i))
            }
            Tok::Sym(_) => None,
        }
    }

    fn interval(&mut self) -> Interval {
        if !self.eat_sym("[") {
            return Interval::ALL;
        }
        let start = self.int();
        let end = if self.eat_sym("..=") {
            Bound::Inclusive(self.int())
        } else {
            self.expect_sym("..");
            if self.peek_sym("]") { Bound::Unbounded } else { Bound::Exclusive(self.int()) }
        };
        self.expect_sym("]");
        Interval { start, end }
    }

    fn int(&mut self) -> usize {
        match self.toks.get(self.pos) {
            Some(Tok::Num(v)) => {
                self.pos += 1;
                *v as usize
            }
            t => panic!("expected an integer, found {t:?}"),
        }
    }
}
