//! Resolution and lowering: state variables, domains, lets, intervals, formulas and
//! expressions of a spec into their checked forms.
//!
//! One file: lowering formulas and expressions and checking the lets they use are one
//! recursive pass over the same names, kept together rather than split mid-recursion.

use super::time::decimal;
use super::*;

impl Cx<'_> {
    pub(super) fn state_block(&mut self, b: &syntax::StateBlock, out: &mut CheckedSpec) {
        for v in &b.vars {
            if v.ty == syntax::VarType::Time {
                self.time_var(v, out);
                continue;
            }
            let domain = self.domain(v);
            if let Some((_, first)) = self.names.get(&v.name.name) {
                let first = first.clone();
                self.push(
                    Diagnostic::new(
                        "HSTL003",
                        v.name.range.clone(),
                        format!("duplicate name `{}`", v.name.name),
                    )
                    .with_label(first, "first defined here")
                    .with_help("rename one of them"),
                );
                continue;
            }
            self.names.insert(
                v.name.name.clone(),
                (NameRef::Var(out.state_vars.len()), v.name.range.clone()),
            );
            out.state_vars.push(StateVarInfo {
                name: v.name.name.clone(),
                ty: v.ty,
                domain,
                doc: doc_text(&v.doc),
                name_range: v.name.range.clone(),
                range: v.range.clone(),
            });
        }
    }

    /// `t: time`: the spec's time variable (at most one, without a range).
    pub(super) fn time_var(&mut self, v: &syntax::StateVar, out: &mut CheckedSpec) {
        if let Some(r) = &v.domain {
            self.push(
                Diagnostic::new(
                    "HSTL080",
                    r.range.clone(),
                    format!("the time variable `{}` has a range", v.name.name),
                )
                .with_help(format!(
                    "time stamps are any strictly increasing numbers: write `{}: time`",
                    v.name.name
                )),
            );
        }
        if let Some(first) = &out.time {
            self.push(
                Diagnostic::new(
                    "HSTL080",
                    v.ty_range.clone(),
                    format!("a second time variable `{}`", v.name.name),
                )
                .with_label(first.name_range.clone(), "the time variable")
                .with_help(format!(
                    "a trace has one time column: make `{}` a `float`, or remove it",
                    v.name.name
                )),
            );
            return;
        }
        if let Some((_, first)) = self.names.get(&v.name.name) {
            let first = first.clone();
            self.push(
                Diagnostic::new(
                    "HSTL003",
                    v.name.range.clone(),
                    format!("duplicate name `{}`", v.name.name),
                )
                .with_label(first, "first defined here")
                .with_help("rename one of them"),
            );
            return;
        }
        self.names.insert(v.name.name.clone(), (NameRef::Time, v.name.range.clone()));
        out.time = Some(TimeVarInfo {
            name: v.name.name.clone(),
            doc: doc_text(&v.doc),
            name_range: v.name.range.clone(),
            range: v.range.clone(),
        });
    }

    /// The time variable used in a formula or an expression.
    pub(super) fn time_in_formula(&mut self, id: &syntax::Ident, def: Range<usize>) {
        self.push(
            Diagnostic::new(
                "HSTL082",
                id.range.clone(),
                format!("`{}` is the time variable: a formula cannot read it", id.name),
            )
            .with_label(def, "declared as the time stamps here")
            .with_help(
                "robustness is a function of time, not of the stamps' values: say when with an \
                 interval, such as `eventually[0..=2.5] x > 1`",
            ),
        );
    }

    pub(super) fn domain(&mut self, v: &syntax::StateVar) -> Domain {
        let Some(r) = &v.domain else { return Domain::Unbounded };
        match v.ty {
            syntax::VarType::Float => {
                let empty =
                    if r.inclusive { r.hi.value < r.lo.value } else { r.hi.value <= r.lo.value };
                if empty {
                    self.push(
                        Diagnostic::new(
                            "HSTL005",
                            r.range.clone(),
                            format!("empty range `{}` for `{}`", self.text(&r.range), v.name.name),
                        )
                        .with_help("the upper bound must exceed the lower one"),
                    );
                    return Domain::Unbounded;
                }
                Domain::Float { lo: r.lo.value, hi: r.hi.value, inclusive: r.inclusive }
            }
            syntax::VarType::Time => Domain::Unbounded,
            syntax::VarType::Int => {
                let lo = self.int_bound(&r.lo, "range");
                let hi = self.int_bound(&r.hi, "range");
                let (Some(lo), Some(hi)) = (lo, hi) else { return Domain::Unbounded };
                let hi_incl = if r.inclusive { hi } else { hi - 1 };
                if hi_incl < lo {
                    let (msg, help) = if hi < lo {
                        ("inverted", "swap the bounds".to_string())
                    } else {
                        (
                            "empty",
                            format!(
                                "`{lo}..{hi}` excludes {hi}: write `{lo}..={hi}` to include it"
                            ),
                        )
                    };
                    self.push(
                        Diagnostic::new(
                            "HSTL005",
                            r.range.clone(),
                            format!("{msg} range `{}` for `{}`", self.text(&r.range), v.name.name),
                        )
                        .with_help(help),
                    );
                    return Domain::Unbounded;
                }
                Domain::Int { lo, hi: hi_incl }
            }
        }
    }

    pub(super) fn text(&self, r: &Range<usize>) -> &str {
        self.src.get(r.clone()).unwrap_or("")
    }

    pub(super) fn int_bound(&mut self, n: &syntax::NumberLit, what: &str) -> Option<i64> {
        // A domain bound may be negative (`-5..=5`); an interval's never is (the grammar).
        let (negative, magnitude) = match n.text.strip_prefix('-') {
            Some(digits) if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) => {
                (true, digits.parse::<u64>().ok())
            }
            _ => (false, n.as_integer()),
        };
        let value = magnitude.and_then(|v| i64::try_from(v).ok()).filter(|&v| v < i64::MAX / 4);
        match value.map(|v| if negative { -v } else { v }) {
            Some(v) => Some(v),
            _ => {
                let digits = n.text.strip_prefix('-').unwrap_or(&n.text);
                let whole = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
                let msg = if whole {
                    format!("{what} bound `{}` is too large", n.text)
                } else {
                    format!("{what} bound `{}` is not a whole number", n.text)
                };
                let help = if what == "interval" && !whole {
                    "interval bounds count steps: write digits only, such as `40`; for bounds \
                     in seconds (`[0..=2.5]`), monitor time-stamped traces: declare the time \
                     column in `state`, such as `t: time`"
                } else {
                    "bounds count steps or integer values: write digits only, such as `40`"
                };
                self.push(Diagnostic::new("HSTL006", n.range.clone(), msg).with_help(help));
                None
            }
        }
    }

    pub(super) fn lets(&mut self, lets: &[&syntax::Let], out: &mut CheckedSpec) {
        // Declare every name first so that lets may refer to later ones.
        let mut kept = Vec::new();
        for l in lets {
            if let Some((_, first)) = self.names.get(&l.name.name) {
                let first = first.clone();
                self.push(
                    Diagnostic::new(
                        "HSTL003",
                        l.name.range.clone(),
                        format!("duplicate name `{}`", l.name.name),
                    )
                    .with_label(first, "first defined here")
                    .with_help("rename one of them"),
                );
                kept.push(false);
                continue;
            }
            let idx = out.lets.len();
            self.names.insert(l.name.name.clone(), (NameRef::Let(idx), l.name.range.clone()));
            out.lets.push(LetInfo {
                name: l.name.name.clone(),
                formula: CFormula { kind: CFormulaKind::Invalid, range: l.formula.range.clone() },
                kind: LetKind::State,
                used: false,
                doc: doc_text(&l.doc),
                name_range: l.name.range.clone(),
                range: l.range.clone(),
            });
            kept.push(true);
        }
        let mut edges: Vec<Vec<(usize, Range<usize>)>> = vec![Vec::new(); out.lets.len()];
        let mut idx = 0;
        for (l, keep) in lets.iter().zip(kept) {
            self.let_refs.clear();
            let f = self.formula(&l.formula);
            if keep {
                out.lets[idx].formula = f;
                edges[idx] = std::mem::take(&mut self.let_refs);
                idx += 1;
            }
        }
        // Kahn's algorithm: lets left over are in or behind a cycle.
        let n = out.lets.len();
        let mut indeg = vec![0usize; n];
        let mut users: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (i, es) in edges.iter().enumerate() {
            for (j, _) in es {
                indeg[i] += 1;
                users[*j].push(i);
            }
        }
        let mut queue: Vec<usize> = (0..n).filter(|&i| indeg[i] == 0).collect();
        let mut order = Vec::new();
        while let Some(j) = queue.pop() {
            order.push(j);
            for &i in &users[j] {
                indeg[i] -= 1;
                if indeg[i] == 0 {
                    queue.push(i);
                }
            }
        }
        let mut placed = vec![false; n];
        for &i in &order {
            placed[i] = true;
        }
        let mut reported = vec![false; n];
        for start in 0..n {
            if placed[start] || reported[start] {
                continue;
            }
            // Follow unplaced references until a let repeats: that is a cycle.
            let mut path: Vec<(usize, Range<usize>)> = Vec::new();
            let mut pos: HashMap<usize, usize> = HashMap::new();
            let mut cur = start;
            let cycle = loop {
                if let Some(&p) = pos.get(&cur) {
                    break path[p..].to_vec();
                }
                pos.insert(cur, path.len());
                let Some((next, r)) = edges[cur].iter().find(|(j, _)| !placed[*j]).cloned() else {
                    break Vec::new();
                };
                path.push((cur, r));
                cur = next;
            };
            if cycle.is_empty() || cycle.iter().any(|(i, _)| reported[*i]) {
                continue;
            }
            for (i, _) in &cycle {
                reported[*i] = true;
            }
            let first = cycle[0].0;
            let lname = &out.lets[first].name;
            let d = if cycle.len() == 1 {
                Diagnostic::new(
                    "HSTL004",
                    out.lets[first].name_range.clone(),
                    format!("`{lname}` refers to itself"),
                )
                .with_label(cycle[0].1.clone(), "here")
            } else {
                let mut names: Vec<String> =
                    cycle.iter().map(|(i, _)| format!("`{}`", out.lets[*i].name)).collect();
                names.push(format!("`{lname}`"));
                let mut d = Diagnostic::new(
                    "HSTL004",
                    out.lets[first].name_range.clone(),
                    format!("`{lname}` refers to itself: {}", names.join(" -> ")),
                );
                for (i, r) in &cycle {
                    let to = match edges[*i].iter().find(|(_, rr)| rr == r) {
                        Some((j, _)) => out.lets[*j].name.clone(),
                        None => String::new(),
                    };
                    d = d
                        .with_label(r.clone(), format!("`{}` uses `{to}` here", out.lets[*i].name));
                }
                d
            };
            self.push(d.with_help("write one of these formulas without the reference"));
        }
        // Kinds, in dependency order; lets in or behind a cycle are judged on their own text.
        let mut temporal = vec![false; n];
        for &i in &order {
            let mut t = has_temporal_node(&out.lets[i].formula);
            for (j, _) in &edges[i] {
                t |= temporal[*j];
            }
            temporal[i] = t;
        }
        for i in 0..n {
            if !placed[i] {
                temporal[i] = has_temporal_node(&out.lets[i].formula);
            }
            out.lets[i].kind = if temporal[i] { LetKind::Temporal } else { LetKind::State };
        }
        // A dependency order with ties broken by declaration order, for stable output.
        out.let_order = dependency_order(&edges, &placed);
    }

    /// A bound of a dense spec's interval, in `10^-time_decimals` of the time unit.
    pub(super) fn time_bound(&mut self, n: &syntax::NumberLit) -> Option<u64> {
        let scaled = decimal(&n.text).and_then(|(m, d)| {
            let p = 10u128.checked_pow(self.time_decimals.checked_sub(d)?)?;
            u64::try_from(m.checked_mul(p)?).ok().filter(|&v| v <= MAX_TIME_BOUND)
        });
        if scaled.is_none() {
            self.push(
                Diagnostic::new(
                    "HSTL006",
                    n.range.clone(),
                    format!("interval bound `{}` is too large or has too many digits", n.text),
                )
                .with_help(format!(
                    "the spec's bounds are counted in units of 10^-{} (its longest fraction): \
                     write at most {} digits in all",
                    self.time_decimals,
                    MAX_TIME_BOUND.to_string().len() - 1
                )),
            );
        }
        scaled
    }

    pub(super) fn interval(&mut self, i: &Option<syntax::Interval>) -> Option<Interval> {
        let Some(i) = i else {
            return Some(Interval { start: 0, end: Bound::Unbounded, range: None });
        };
        if self.dense {
            return self.dense_interval(i);
        }
        let a = self.int_bound(&i.start, "interval");
        let b = match &i.end {
            Some(e) => Some(self.int_bound(e, "interval")?),
            None => None,
        };
        let a = a?;
        let end = match b {
            None => Bound::Unbounded,
            Some(b) => {
                let empty = if i.inclusive { b < a } else { b <= a };
                if empty {
                    let text = self.text(&i.range).to_string();
                    let (msg, help) = if b < a {
                        (format!("inverted interval `{text}`"), "swap the bounds".to_string())
                    } else {
                        (
                            format!("empty interval `{text}`"),
                            format!(
                                "`[{a}..{b}]` excludes step {b}: write `[{a}..={b}]` for that single step"
                            ),
                        )
                    };
                    self.push(Diagnostic::new("HSTL005", i.range.clone(), msg).with_help(help));
                    return None;
                }
                if i.inclusive { Bound::Inclusive(b as u64) } else { Bound::Exclusive(b as u64) }
            }
        };
        Some(Interval { start: a as u64, end, range: Some(i.range.clone()) })
    }

    /// An interval of a dense-time spec: decimal bounds, closed or unbounded.
    pub(super) fn dense_interval(&mut self, i: &syntax::Interval) -> Option<Interval> {
        let a = self.time_bound(&i.start);
        let b = match &i.end {
            Some(e) => Some(self.time_bound(e)?),
            None => None,
        };
        let a = a?;
        let text = self.text(&i.range).to_string();
        let end = match b {
            None => Bound::Unbounded,
            Some(_) if !i.inclusive => {
                let lo = &i.start.text;
                let hi = i.end.as_ref().map_or("", |e| e.text.as_str());
                self.push(
                    Diagnostic::new(
                        "HSTL081",
                        i.range.clone(),
                        format!("the half-open interval `{text}` has no dense-time meaning"),
                    )
                    .with_help(format!(
                        "it would give values that hold at single instants: write the closed \
                         interval `[{lo}..={hi}]`"
                    )),
                );
                return None;
            }
            Some(b) if b < a => {
                self.push(
                    Diagnostic::new(
                        "HSTL005",
                        i.range.clone(),
                        format!("inverted interval `{text}`"),
                    )
                    .with_help("swap the bounds"),
                );
                return None;
            }
            Some(b) => Bound::Inclusive(b),
        };
        Some(Interval { start: a, end, range: Some(i.range.clone()) })
    }

    /// `prev` or `next` in a dense-time spec.
    pub(super) fn no_dense_step(&mut self, f: &Formula, op: &str) {
        let at = f.range.start..(f.range.start + op.len()).min(f.range.end);
        self.push(
            Diagnostic::new("HSTL081", at, format!("`{op}` has no dense-time meaning")).with_help(
                format!(
                    "in continuous time there is no {} sample: say how far with an interval, such \
                 as `{}[0..=0.1] f`",
                    if op == "prev" { "previous" } else { "next" },
                    if op == "prev" { "once" } else { "eventually" }
                ),
            ),
        );
    }

    pub(super) fn formula(&mut self, f: &Formula) -> CFormula {
        let range = f.range.clone();
        let invalid = CFormula { kind: CFormulaKind::Invalid, range: range.clone() };
        let kind = match &f.kind {
            FormulaKind::True => CFormulaKind::True,
            FormulaKind::False => CFormulaKind::False,
            FormulaKind::Paren(g) => return self.formula(g),
            FormulaKind::Name(id) => match self.names.get(&id.name) {
                Some((NameRef::Let(j), _)) => {
                    let j = *j;
                    self.let_refs.push((j, id.range.clone()));
                    CFormulaKind::Let(j)
                }
                Some((NameRef::Time, def)) => {
                    let def = def.clone();
                    self.time_in_formula(id, def);
                    return invalid;
                }
                Some((NameRef::Var(_), def)) => {
                    let def = def.clone();
                    self.push(
                        Diagnostic::new(
                            "HSTL008",
                            id.range.clone(),
                            format!("`{}` is a state variable, not a formula", id.name),
                        )
                        .with_label(def, "declared here")
                        .with_help(format!("compare it, such as `{} > 0`", id.name)),
                    );
                    return invalid;
                }
                None => {
                    self.unknown(id, true);
                    return invalid;
                }
            },
            FormulaKind::Compare { first, rest } => {
                let mut parts = Vec::new();
                let mut lhs = self.expr(first);
                let mut ok = true;
                for (k, (op, op_range, e)) in rest.iter().enumerate() {
                    let rhs = self.expr(e);
                    let cop = match op {
                        syntax::CmpOp::Lt => Some(CmpOp::Lt),
                        syntax::CmpOp::Le => Some(CmpOp::Le),
                        syntax::CmpOp::Gt => Some(CmpOp::Gt),
                        syntax::CmpOp::Ge => Some(CmpOp::Ge),
                        syntax::CmpOp::Eq | syntax::CmpOp::Ne => {
                            self.push(
                                Diagnostic::new(
                                    "HSTL007",
                                    op_range.clone(),
                                    format!("`{}` has no robustness", op.as_str()),
                                )
                                .with_help("use a band, such as `abs(x - 3) < 0.5`"),
                            );
                            None
                        }
                    };
                    match cop {
                        // The last expression is moved, not copied: it ends the chain.
                        Some(c) if k + 1 == rest.len() => {
                            let range = lhs.range.start..rhs.range.end;
                            parts.push(CFormula { range, kind: CFormulaKind::Cmp(c, lhs, rhs) });
                            break;
                        }
                        Some(c) => {
                            let next = rhs.clone();
                            let range = lhs.range.start..rhs.range.end;
                            parts.push(CFormula { range, kind: CFormulaKind::Cmp(c, lhs, rhs) });
                            lhs = next;
                        }
                        None => {
                            ok = false;
                            lhs = rhs;
                        }
                    }
                }
                if !ok {
                    return invalid;
                }
                if parts.len() == 1 {
                    return parts.pop().unwrap_or(invalid);
                }
                CFormulaKind::And(parts)
            }
            FormulaKind::Not(g) => CFormulaKind::Not(Box::new(self.formula(g))),
            FormulaKind::Always(i, g) => self.windowed(i, g, CFormulaKind::Always),
            FormulaKind::Eventually(i, g) => self.windowed(i, g, CFormulaKind::Eventually),
            FormulaKind::Until(a, i, b) => self.windowed2(a, i, b, CFormulaKind::Until),
            FormulaKind::Once(i, g) => self.windowed(i, g, CFormulaKind::Once),
            FormulaKind::Historically(i, g) => self.windowed(i, g, CFormulaKind::Historically),
            FormulaKind::Since(a, i, b) => self.windowed2(a, i, b, CFormulaKind::Since),
            FormulaKind::Prev(g) if self.dense => {
                self.no_dense_step(f, "prev");
                self.formula(g);
                return invalid;
            }
            FormulaKind::Next(g) if self.dense => {
                self.no_dense_step(f, "next");
                self.formula(g);
                return invalid;
            }
            FormulaKind::Prev(g) => CFormulaKind::Prev(Box::new(self.formula(g))),
            FormulaKind::Next(g) => CFormulaKind::Next(Box::new(self.formula(g))),
            FormulaKind::And(v) => CFormulaKind::And(v.iter().map(|g| self.formula(g)).collect()),
            FormulaKind::Or(v) => CFormulaKind::Or(v.iter().map(|g| self.formula(g)).collect()),
            FormulaKind::Implies(a, b) => {
                CFormulaKind::Implies(Box::new(self.formula(a)), Box::new(self.formula(b)))
            }
        };
        CFormula { kind, range }
    }

    /// A windowed operator of one operand: its interval checked, then its operand, built
    /// by `make`; `Invalid` when the interval did not check.
    fn windowed(
        &mut self,
        i: &Option<syntax::Interval>,
        g: &Formula,
        make: fn(Interval, Box<CFormula>) -> CFormulaKind,
    ) -> CFormulaKind {
        let iv = self.interval(i);
        let g = self.formula(g);
        iv.map_or(CFormulaKind::Invalid, |iv| make(iv, Box::new(g)))
    }

    /// A windowed operator of two operands (`until`, `since`), checked left to right.
    fn windowed2(
        &mut self,
        a: &Formula,
        i: &Option<syntax::Interval>,
        b: &Formula,
        make: fn(Interval, Box<CFormula>, Box<CFormula>) -> CFormulaKind,
    ) -> CFormulaKind {
        let a = self.formula(a);
        let iv = self.interval(i);
        let b = self.formula(b);
        iv.map_or(CFormulaKind::Invalid, |iv| make(iv, Box::new(a), Box::new(b)))
    }

    pub(super) fn unknown(&mut self, id: &syntax::Ident, formula: bool) {
        if self.broken_names.contains(&id.name) {
            return;
        }
        let want = if formula { NameRef::Let(0) } else { NameRef::Var(0) };
        let same_kind = |r: &NameRef| {
            matches!(
                (r, want),
                (NameRef::Let(_), NameRef::Let(_)) | (NameRef::Var(_), NameRef::Var(_))
            )
        };
        let cands = self.names.iter().filter(|(_, (r, _))| same_kind(r)).map(|(n, _)| n.as_str());
        let mut d =
            Diagnostic::new("HSTL002", id.range.clone(), format!("unknown name `{}`", id.name));
        d = match closest(&id.name, cands, &mut self.suggest_budget) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None if formula => d.with_help(format!("declare it: `let {} = ...;`", id.name)),
            None => d.with_help(format!("declare it in `state {{ {}: int in 0..=9 }}`", id.name)),
        };
        self.push(d);
    }

    pub(super) fn expr(&mut self, e: &syntax::Expr) -> CExpr {
        use syntax::ExprKind as K;
        let range = e.range.clone();
        let invalid = CExpr { kind: CExprKind::Invalid, range: range.clone() };
        let kind = match &e.kind {
            K::Number(n) => CExprKind::Const(n.value),
            K::Paren(a) => return self.expr(a),
            K::Name(id) => match self.names.get(&id.name) {
                Some((NameRef::Var(i), _)) => CExprKind::Var(*i),
                Some((NameRef::Time, def)) => {
                    let def = def.clone();
                    self.time_in_formula(id, def);
                    return invalid;
                }
                Some((NameRef::Let(_), def)) => {
                    let def = def.clone();
                    self.push(
                        Diagnostic::new(
                            "HSTL008",
                            id.range.clone(),
                            format!("`{}` is a formula, not a number", id.name),
                        )
                        .with_label(def, "defined here")
                        .with_help("comparisons relate numbers: state variables, constants and arithmetic; combine formulas with `&&`, `||`"),
                    );
                    return invalid;
                }
                None => {
                    self.unknown(id, false);
                    return invalid;
                }
            },
            K::Neg(a) => CExprKind::Neg(Box::new(self.expr(a))),
            K::Call(f, a) => {
                let a = Box::new(self.expr(a));
                match f {
                    syntax::Func::Abs => CExprKind::Abs(a),
                    syntax::Func::Sqrt => CExprKind::Sqrt(a),
                }
            }
            K::Binary(op, a, b) => {
                let (a, b) = (Box::new(self.expr(a)), Box::new(self.expr(b)));
                match op {
                    syntax::BinOp::Add => CExprKind::Add(a, b),
                    syntax::BinOp::Sub => CExprKind::Sub(a, b),
                    syntax::BinOp::Mul => CExprKind::Mul(a, b),
                    syntax::BinOp::Div => CExprKind::Div(a, b),
                }
            }
        };
        CExpr { kind, range }
    }

    /// Where a formula stops being a state formula: the temporal node, or a let reference
    /// to a temporal let (with that let's name range).
    pub(super) fn temporal_site(&self, f: &CFormula, lets: &[LetInfo]) -> Option<TemporalSite> {
        match &f.kind {
            kind if kind.is_temporal() => Some((f.range.clone(), None)),
            CFormulaKind::Let(i) => {
                let l = lets.get(*i)?;
                (l.kind == LetKind::Temporal)
                    .then(|| (f.range.clone(), Some((l.name_range.clone(), l.name.clone()))))
            }
            CFormulaKind::Not(a) => self.temporal_site(a, lets),
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                v.iter().find_map(|g| self.temporal_site(g, lets))
            }
            CFormulaKind::Implies(a, b) => {
                self.temporal_site(a, lets).or_else(|| self.temporal_site(b, lets))
            }
            _ => None,
        }
    }

    pub(super) fn require_state(
        &mut self,
        f: &CFormula,
        field: &str,
        option: &str,
        lets: &[LetInfo],
    ) {
        if let Some((r, via)) = self.temporal_site(f, lets) {
            let mut d = Diagnostic::new(
                "HSTL009",
                r,
                format!("temporal operator in the `{field}` of option `{option}`"),
            )
            .with_help("reach, init and terminate are evaluated on one state: use a formula without temporal operators (`always`, `eventually`, `until`, `once`, `historically`, `since`, `prev`, `next`)");
            if let Some((lr, name)) = via {
                d = d.with_label(lr, format!("`{name}` is a temporal formula"));
            }
            self.push(d);
        }
    }
}

/// Where a formula stops being a state formula, and the temporal let it goes through.
pub(super) type TemporalSite = (Range<usize>, Option<(Range<usize>, String)>);

pub(super) fn has_temporal_node(f: &CFormula) -> bool {
    match &f.kind {
        kind if kind.is_temporal() => true,
        CFormulaKind::Not(a) => has_temporal_node(a),
        CFormulaKind::And(v) | CFormulaKind::Or(v) => v.iter().any(has_temporal_node),
        CFormulaKind::Implies(a, b) => has_temporal_node(a) || has_temporal_node(b),
        _ => false,
    }
}

/// Lets in an order where each comes after the lets it uses, ties by declaration order;
/// lets not placed (in or behind a cycle) are left out.
pub(super) fn dependency_order(
    edges: &[Vec<(usize, Range<usize>)>],
    placed: &[bool],
) -> Vec<usize> {
    let n = edges.len();
    let mut indeg = vec![0usize; n];
    let mut users: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, es) in edges.iter().enumerate() {
        for (j, _) in es {
            indeg[i] += 1;
            users[*j].push(i);
        }
    }
    let mut heap: std::collections::BinaryHeap<std::cmp::Reverse<usize>> =
        (0..n).filter(|&i| indeg[i] == 0 && placed[i]).map(std::cmp::Reverse).collect();
    let mut order = Vec::new();
    while let Some(std::cmp::Reverse(j)) = heap.pop() {
        order.push(j);
        for &i in &users[j] {
            indeg[i] -= 1;
            if indeg[i] == 0 && placed[i] {
                heap.push(std::cmp::Reverse(i));
            }
        }
    }
    order
}
