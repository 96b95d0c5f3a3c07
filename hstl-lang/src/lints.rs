//! Checks that keep a spec from failing later, in `train` or in files it names, or from
//! meaning something else than it seems: `HSTL050` (a reach formula that refers to no
//! state variable), `HSTL104` (a task that refers to none), `HSTL051` (a name longer than [`MAX_NAME_CHARS`]) and `HSTL150`
//! (`<=` or `>=` against a whole number on an `int` variable), `HSTL060` (an expression
//! that is NaN on a state of the declared `int` domain), and `HSTL190` (a past window
//! without an end where option runs are long).

use crate::checked::{
    Bound, CExpr, CExprKind, CFormula, CFormulaKind, CheckedSpec, CmpOp, Terminate, VarType,
};
use crate::diagnostic::Diagnostic;
use crate::syntax;

/// The longest name a spec may declare, in characters. Names become file names (the
/// pictures `train` writes, such as `flat_NAME.svg`), which most file systems cap at 255
/// bytes, and they are shown in tables and pictures.
pub const MAX_NAME_CHARS: usize = 64;

/// `HSTL051` for every declared name (spec, state variables, lets, options) longer than
/// [`MAX_NAME_CHARS`].
pub(crate) fn long_names(spec: &syntax::Spec, out: &mut Vec<Diagnostic>) {
    let mut names: Vec<(&syntax::Ident, &str)> = vec![(&spec.name, "spec")];
    for item in &spec.items {
        match item {
            syntax::Item::State(b) => {
                names.extend(b.vars.iter().map(|v| (&v.name, "state variable")))
            }
            syntax::Item::Let(l) => names.push((&l.name, "`let`")),
            syntax::Item::Option(o) => names.push((&o.name, "option")),
            _ => {}
        }
    }
    for (ident, what) in names {
        let chars = ident.name.chars().count();
        if chars > MAX_NAME_CHARS {
            out.push(
                Diagnostic::new(
                    "HSTL051",
                    ident.range.clone(),
                    format!(
                        "this {what} name is {chars} characters long, more than {MAX_NAME_CHARS}"
                    ),
                )
                .with_help(format!("shorten it to at most {MAX_NAME_CHARS} characters")),
            );
        }
    }
}

/// Whether the spec's task refers to no state variable, directly or through lets: its
/// robustness is the same at every step, so training has nothing to learn from it
/// (`HSTL104`, which `train` refuses).
pub fn task_is_constant(spec: &CheckedSpec) -> bool {
    let reads_state = lets_reading_state(spec);
    spec.task.as_ref().is_some_and(|t| !refers_to_state(&t.formula, &reads_state))
}

/// Per let: whether it refers to the state, directly or through lets. Lets left out of the
/// dependency order (cycles, reported already) count as referring to it.
fn lets_reading_state(spec: &CheckedSpec) -> Vec<bool> {
    let mut reads_state = vec![true; spec.lets.len()];
    for &i in &spec.let_order {
        reads_state[i] = refers_to_state(&spec.lets[i].formula, &reads_state);
    }
    reads_state
}

/// `HSTL104` (a warning) for a task that refers to no state variable, and `HSTL050` (an
/// error) for a primitive option's `reach` that does not: the task's robustness is the same
/// at every step (`inf` for `true`), which can be monitored but not learnt from, and the
/// option's reward is the same in every state.
pub(crate) fn constant_formulas(spec: &CheckedSpec, out: &mut Vec<Diagnostic>) {
    let reads_state = lets_reading_state(spec);
    if let Some(task) = &spec.task
        && !refers_to_state(&task.formula, &reads_state)
    {
        out.push(
            Diagnostic::new(
                "HSTL104",
                task.formula.range.clone(),
                "the task refers to no state variable: its robustness is the same at every step",
            )
            .with_help(
                "write the task over the state, such as `task always[0..] eventually[0..40] A;` \
                 with `let A = x > 3;`",
            ),
        );
    }
    for p in &spec.primitives {
        if !refers_to_state(&p.reach, &reads_state) {
            out.push(
                Diagnostic::new(
                    "HSTL050",
                    p.reach.range.clone(),
                    format!(
                        "option `{}` reaches a formula that refers to no state variable: its \
                         reward is the same in every state",
                        p.name
                    ),
                )
                .with_help("reach a region of the state, such as `let A = x > 3;`"),
            );
        }
    }
}

/// Whether `f` reads a state variable (an invalid part counts as reading one: it was
/// reported already). Walks the tree with a stack, not recursion.
fn refers_to_state(f: &CFormula, lets: &[bool]) -> bool {
    let mut formulas = vec![f];
    let mut exprs: Vec<&CExpr> = Vec::new();
    while let Some(f) = formulas.pop() {
        match &f.kind {
            CFormulaKind::True | CFormulaKind::False => {}
            CFormulaKind::Invalid => return true,
            CFormulaKind::Let(i) => {
                if lets.get(*i).copied().unwrap_or(true) {
                    return true;
                }
            }
            CFormulaKind::Cmp(_, a, b) => exprs.extend([a, b]),
            _ => formulas.extend(f.operands()),
        }
    }
    while let Some(e) = exprs.pop() {
        match &e.kind {
            CExprKind::Const(_) => {}
            CExprKind::Var(_) | CExprKind::Invalid => return true,
            CExprKind::Neg(a) | CExprKind::Abs(a) | CExprKind::Sqrt(a) => exprs.push(a),
            CExprKind::Add(a, b)
            | CExprKind::Sub(a, b)
            | CExprKind::Mul(a, b)
            | CExprKind::Div(a, b) => exprs.extend([&**a, &**b]),
        }
    }
    false
}

/// `HSTL150` for each comparison (or chain of comparisons) that puts `<=` or `>=` between
/// an `int` state variable and a whole number: robustness is a difference, so at the
/// bound it is exactly 0, which does not satisfy the comparison, and `2 <= y <= 3` holds
/// in no cell. The help rewrites it with strict comparisons, which mean what was meant.
pub(crate) fn inclusive_int_bounds(spec: &CheckedSpec, src: &str, out: &mut Vec<Diagnostic>) {
    let mut roots: Vec<&CFormula> = spec.lets.iter().map(|l| &l.formula).collect();
    roots.extend(spec.task.iter().map(|t| &t.formula));
    for p in &spec.primitives {
        roots.extend([&p.reach, &p.init]);
        if let Terminate::Formula(f) = &p.terminate {
            roots.push(f);
        }
    }
    let mut stack = roots;
    while let Some(f) = stack.pop() {
        match &f.kind {
            CFormulaKind::And(parts) if is_chain(parts) => {
                chain_warning(spec, src, f, parts, out);
            }
            CFormulaKind::Cmp(..) => chain_warning(spec, src, f, std::slice::from_ref(f), out),
            _ => stack.extend(f.operands()),
        }
    }
}

/// Whether `parts` came from one chain such as `1 < x <= 4`: comparisons where each one's
/// right side is the next one's left side.
fn is_chain(parts: &[CFormula]) -> bool {
    parts.windows(2).all(|w| match (&w[0].kind, &w[1].kind) {
        (CFormulaKind::Cmp(_, _, r), CFormulaKind::Cmp(_, l, _)) => r.range == l.range,
        _ => false,
    })
}

/// One warning for the comparisons of `parts` (a chain, or one comparison) if any of them
/// puts `<=` or `>=` between an `int` variable and a whole number.
fn chain_warning(
    spec: &CheckedSpec,
    src: &str,
    f: &CFormula,
    parts: &[CFormula],
    out: &mut Vec<Diagnostic>,
) {
    // The chain as operands and the operators between them.
    let mut operands: Vec<&CExpr> = Vec::with_capacity(parts.len() + 1);
    let mut ops: Vec<CmpOp> = Vec::with_capacity(parts.len());
    for part in parts {
        let CFormulaKind::Cmp(op, lhs, rhs) = &part.kind else { return };
        if operands.is_empty() {
            operands.push(lhs);
        }
        operands.push(rhs);
        ops.push(*op);
    }
    // A whole-number operand next to an `int` variable moves by one where `<=` or `>=`
    // becomes strict: `x <= 3` is `x < 4`, `2 <= x` is `1 < x`.
    let mut moved: Vec<Option<i64>> = vec![None; operands.len()];
    let mut strict = vec![false; ops.len()];
    let mut trapped: Option<(&str, i64)> = None;
    for (k, op) in ops.iter().enumerate() {
        let up = match op {
            CmpOp::Le => true,
            CmpOp::Ge => false,
            CmpOp::Lt | CmpOp::Gt => continue,
        };
        let (var, bound, at, step) = match (
            int_var(spec, operands[k]),
            whole(operands[k + 1]),
            whole(operands[k]),
            int_var(spec, operands[k + 1]),
        ) {
            // `x <= b`: b + 1; `x >= b`: b - 1.
            (Some(v), Some(b), _, _) => (v, b, k + 1, if up { 1 } else { -1 }),
            // `b <= x`: b - 1; `b >= x`: b + 1.
            (_, _, Some(b), Some(v)) => (v, b, k, if up { -1 } else { 1 }),
            _ => continue,
        };
        let Some(new) = bound.checked_add(step) else { return };
        if moved[at].is_some_and(|m| m != new) {
            // One number bounds two comparisons in opposite ways: no simple rewrite.
            return;
        }
        moved[at] = Some(new);
        strict[k] = true;
        trapped.get_or_insert((var, bound));
    }
    let Some((var, bound)) = trapped else { return };
    let mut rewritten = String::new();
    for (k, e) in operands.iter().enumerate() {
        if k > 0 {
            rewritten.push_str(match (ops[k - 1], strict[k - 1]) {
                (CmpOp::Lt, _) | (CmpOp::Le, true) => " < ",
                (CmpOp::Le, false) => " <= ",
                (CmpOp::Gt, _) | (CmpOp::Ge, true) => " > ",
                (CmpOp::Ge, false) => " >= ",
            });
        }
        match moved[k] {
            Some(v) => rewritten.push_str(&v.to_string()),
            None => rewritten.push_str(src.get(e.range.clone()).unwrap_or("...").trim()),
        }
    }
    out.push(
        Diagnostic::new(
            "HSTL150",
            f.range.clone(),
            format!(
                "`<=` or `>=` on the `int` variable `{var}`: at `{var} = {bound}` the robustness \
                 is 0, which does not satisfy the comparison"
            ),
        )
        .with_help(format!("on integer cells write `{rewritten}`")),
    );
}

/// The name of the `int` state variable `e` is, if it is one.
fn int_var<'s>(spec: &'s CheckedSpec, e: &CExpr) -> Option<&'s str> {
    match e.kind {
        CExprKind::Var(i) => {
            spec.state_vars.get(i).filter(|v| v.ty == VarType::Int).map(|v| v.name.as_str())
        }
        _ => None,
    }
}

/// The whole number `e` is, if it is one.
fn whole(e: &CExpr) -> Option<i64> {
    match e.kind {
        CExprKind::Const(c) if c.fract() == 0.0 && c.abs() < 1e15 => Some(c as i64),
        CExprKind::Neg(ref a) => whole(a).map(|v| -v),
        _ => None,
    }
}

/// `HSTL060` for each comparison whose expressions are NaN on some state of the declared
/// `int` domain (`sqrt` of a negative, `0 / 0`, ...), at the innermost expression that is,
/// naming the first such state. Runs when every state variable is a finite `int` and the
/// domain times the comparisons is within the finite-domain checks' budget.
pub(crate) fn undefined_expressions(spec: &CheckedSpec, src: &str, out: &mut Vec<Diagnostic>) {
    let Some(size) = spec.domain_size() else { return };
    if spec.state_vars.is_empty() || size > crate::limits::MAX_DOMAIN_STATES {
        return;
    }
    let mut atoms: Vec<(&CExpr, &CExpr, &std::ops::Range<usize>)> = Vec::new();
    let mut stack: Vec<&CFormula> = spec.lets.iter().map(|l| &l.formula).collect();
    if let Some(task) = &spec.task {
        stack.push(&task.formula);
    }
    for p in &spec.primitives {
        stack.push(&p.reach);
        stack.push(&p.init);
        if let Terminate::Formula(f) = &p.terminate {
            stack.push(f);
        }
    }
    // Each comparison once: a `let` is walked once, and a range names one source place.
    let mut seen = std::collections::HashSet::new();
    while let Some(f) = stack.pop() {
        if let CFormulaKind::Cmp(_, a, b) = &f.kind
            && nan_prone(a, b)
            && seen.insert(f.range.start)
        {
            atoms.push((a, b, &f.range));
        }
        stack.extend(f.operands());
    }
    if atoms.is_empty() || size.saturating_mul(atoms.len() as u64) > crate::limits::MAX_DOMAIN_WORK
    {
        return;
    }
    atoms.sort_by_key(|(_, _, r)| r.start);
    let widths: Vec<(i64, u64)> = spec
        .state_vars
        .iter()
        .map(|v| match v.domain {
            crate::checked::Domain::Int { lo, hi } => (lo, (hi as i128 - lo as i128 + 1) as u64),
            _ => (0, 1),
        })
        .collect();
    let mut state = vec![0.0; widths.len()];
    let mut open: Vec<bool> = vec![true; atoms.len()];
    for k in 0..size {
        let mut rest = k;
        for (v, &(lo, w)) in state.iter_mut().zip(&widths).rev() {
            *v = (lo as i128 + (rest % w) as i128) as f64;
            rest /= w;
        }
        for (a, &(lhs, rhs, range)) in atoms.iter().enumerate() {
            if !open[a] {
                continue;
            }
            let cause = match (value(lhs, &state), value(rhs, &state)) {
                (Err(c), _) | (_, Err(c)) => Some(c),
                (Ok(l), Ok(r)) if (l - r).is_nan() => {
                    Some((range.clone(), format!("the comparison of {l} with {r}")))
                }
                _ => None,
            };
            let Some((at, operation)) = cause else { continue };
            open[a] = false;
            let valuation: Vec<String> = spec
                .state_vars
                .iter()
                .zip(&state)
                .map(|(v, x)| format!("{} = {x}", v.name))
                .collect();
            let text = src.get(at.clone()).unwrap_or("the expression");
            out.push(
                Diagnostic::new(
                    "HSTL060",
                    at,
                    format!("`{text}` is NaN at {}: {operation}", valuation.join(", ")),
                )
                .with_help(
                    "robustness has no meaning for NaN: keep the expression defined on the whole \
                     declared domain (for example `sqrt(abs(...))`), or narrow the `int` ranges",
                ),
            );
        }
        if !open.iter().any(|&o| o) {
            break;
        }
    }
}

/// Whether `a op b` can be NaN on a state: not when one side is a finite constant and the
/// other a variable or a finite constant.
fn nan_prone(a: &CExpr, b: &CExpr) -> bool {
    let finite = |e: &CExpr| matches!(e.kind, CExprKind::Const(c) if c.is_finite());
    let plain = |e: &CExpr| matches!(e.kind, CExprKind::Var(_) | CExprKind::Const(_));
    !((finite(a) && plain(b)) || (finite(b) && plain(a)))
}

/// The value of `e` on `s`, or the innermost expression that is NaN and what it computed.
/// Expressions are as deep as the parser's nesting limits allow, so this recursion is
/// bounded.
fn value(e: &CExpr, s: &[f64]) -> Result<f64, (std::ops::Range<usize>, String)> {
    let binary = |a: &CExpr, b: &CExpr, op: fn(f64, f64) -> f64, sym: &str| {
        let (a, b) = (value(a, s)?, value(b, s)?);
        let v = op(a, b);
        if v.is_nan() { Err((e.range.clone(), format!("{a} {sym} {b}"))) } else { Ok(v) }
    };
    match &e.kind {
        CExprKind::Const(c) => Ok(*c),
        CExprKind::Var(i) => Ok(s.get(*i).copied().unwrap_or(0.0)),
        CExprKind::Neg(a) => Ok(-value(a, s)?),
        CExprKind::Abs(a) => Ok(value(a, s)?.abs()),
        CExprKind::Sqrt(a) => {
            let v = value(a, s)?;
            if v < 0.0 {
                Err((e.range.clone(), format!("the square root of {v}")))
            } else {
                Ok(v.sqrt())
            }
        }
        CExprKind::Add(a, b) => binary(a, b, |a, b| a + b, "+"),
        CExprKind::Sub(a, b) => binary(a, b, |a, b| a - b, "-"),
        CExprKind::Mul(a, b) => binary(a, b, |a, b| a * b, "*"),
        CExprKind::Div(a, b) => binary(a, b, |a, b| a / b, "/"),
        // An invalid part was reported already.
        CExprKind::Invalid => Ok(0.0),
    }
}

/// How many steps the suffixes of one option run may evaluate on their own, per step of
/// the run: `hstl_robustness::segment::SUFFIX_BUDGET`, twinned here because the language
/// crate depends on no robustness (`tests/limits.rs` holds them equal). Past it, training
/// scores only every `s`-th suffix of a run.
pub const SUFFIX_BUDGET: u64 = 256;

/// About one suffix in how many training scores in runs of `max_steps` steps when a past
/// window reads `reach` steps back (`None`: without an end): the steps the suffixes read on
/// their own over the budget, 1 when every suffix is scored. A lower bound: the task's
/// horizon adds to what each suffix reads.
pub fn suffix_stride(reach: Option<u64>, max_steps: u64) -> u64 {
    let m = u128::from(max_steps) + 1;
    // The suffix from `i` reads `min(m - i, r)` steps on its own.
    let all = m * (m + 1) / 2;
    let total = match reach.map(u128::from) {
        Some(w) if w < m => w * (m - w) + w * (w + 1) / 2,
        _ => all,
    };
    let every = total.div_ceil(u128::from(SUFFIX_BUDGET) * m).max(1);
    u64::try_from(every).unwrap_or(u64::MAX)
}

/// `HSTL190` (a warning) for a past window (`once`, `historically`, `since`) without an
/// end, or longer than [`SUFFIX_BUDGET`], in a task rewarded by segment: such a window
/// reads back to each suffix's own start, so on long runs training scores only some of a
/// run's suffixes for the intra-option updates, to keep each run linear in its length.
/// Walks the task and the lets it uses with a stack, each let once.
pub(crate) fn unbounded_past_in_long_runs(spec: &CheckedSpec, out: &mut Vec<Diagnostic>) {
    let learn = &spec.learn;
    let Some(task) = &spec.task else { return };
    if learn.reward != crate::checked::Reward::Segment {
        return;
    }
    let mut seen = vec![false; spec.lets.len()];
    let mut stack = vec![&task.formula];
    while let Some(f) = stack.pop() {
        let (name, interval) = match &f.kind {
            CFormulaKind::Once(i, _) => ("once", i),
            CFormulaKind::Historically(i, _) => ("historically", i),
            CFormulaKind::Since(i, ..) => ("since", i),
            CFormulaKind::Let(k) => {
                if let Some(l) = spec.lets.get(*k)
                    && !std::mem::replace(&mut seen[*k], true)
                {
                    stack.push(&l.formula);
                }
                continue;
            }
            _ => {
                stack.extend(f.operands());
                continue;
            }
        };
        stack.extend(f.operands());
        let reach = match interval.end {
            Bound::Unbounded => None,
            Bound::Inclusive(b) => Some(b),
            Bound::Exclusive(b) => Some(b.saturating_sub(1)),
        };
        let steps = learn.max_steps;
        let every = suffix_stride(reach, steps);
        if every <= 1 {
            continue;
        }
        let (what, or) = match reach {
            None => (
                "without an end reads back to the start of each suffix of a run".to_owned(),
                "; or keep `max_steps` at 500 or less",
            ),
            Some(r) => (format!("reads {} steps back", crate::wording::thousands(r)), ""),
        };
        out.push(
            Diagnostic::new(
                "HSTL190",
                f.range.clone(),
                format!(
                    "`{name}` {what}: so that each run costs time linear in its length, \
                     training scores only about one suffix in {every} for the options level \
                     at `max_steps: {steps}`"
                ),
            )
            .with_help(format!(
                "give the window an end of at most 256 steps, such as `{name}[{}..={}]`, to \
                 score every suffix{or}",
                interval.start,
                interval.start.saturating_add(100)
            )),
        );
    }
}
