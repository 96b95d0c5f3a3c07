//! Hover: on a name, what it is (a state variable's domain, a `let`'s kind and how many
//! states satisfy it, an option's legs); on an operator, its robustness meaning and its
//! interval in words; on a `world` item's string, the world; on `preset`, what it stands
//! for. Markdown text over a byte range.

use std::ops::Range;

use hstl::lang::check::MAX_DOMAIN_STATES;
use hstl::lang::syntax::{self, CmpOp, FieldValue, Formula, FormulaKind, Interval, Item};
use hstl::lang::{CheckedSpec, Domain, LetKind, StateEvaluator};

use crate::analysis::{Analysis, SymKind, Symbol};

/// Hover text: for a name, what it is; for an operator, its robustness meaning and its
/// interval in words.
pub fn hover(a: &Analysis, offset: usize) -> Option<(Range<usize>, String)> {
    // On `option A;` the name is both the option and the let it reaches: the option's
    // hover, which names the let, is what the line is about.
    let option = a.occurrences_at(offset).find(|o| o.symbol.kind == SymKind::Option);
    match option.or_else(|| a.symbol_at(offset)) {
        Some(o) => Some((o.range.clone(), symbol_hover(a, &o.symbol)?)),
        None => preset_hover(a, offset)
            .or_else(|| world_hover(a, offset))
            .or_else(|| operator_hover(a, offset)),
    }
}

/// The `world` item whose string holds `offset`, quotes included.
pub(crate) fn world_at(a: &Analysis, offset: usize) -> Option<&syntax::WorldItem> {
    a.checked.file.specs.iter().flat_map(|s| &s.items).find_map(|i| match i {
        Item::World(w) if w.name_range.start <= offset && offset <= w.name_range.end => Some(w),
        _ => None,
    })
}

/// On a `world` item's string: the world it names (its size and slip), or why it cannot be
/// had.
fn world_hover(a: &Analysis, offset: usize) -> Option<(Range<usize>, String)> {
    let item = world_at(a, offset)?;
    let resolved = a.worlds.get(&item.name)?;
    let text = match resolved.world.as_ref() {
        Ok((_, words)) => format!(
            "**{words}**: the world this spec is written for; `hstlc check`, `train` and \
             `study` use it (`--world` overrides it)"
        ),
        Err(problem) => format!("**world unavailable**: {}", problem.message),
    };
    Some((item.name_range.clone(), text))
}

/// On `preset` in a `learn` item (its name or its value): what the preset sets, and for
/// `auto` what it expanded to in this spec.
fn preset_hover(a: &Analysis, offset: usize) -> Option<(Range<usize>, String)> {
    for (i, spec) in a.checked.file.specs.iter().enumerate() {
        for item in &spec.items {
            let Item::Learn(l) = item else { continue };
            let Some(p) = l.params.iter().find(|p| {
                p.name.name == "preset" && p.range.start <= offset && offset <= p.range.end
            }) else {
                continue;
            };
            let text = match a.checked_spec(i).and_then(|c| c.preset_expansion.as_ref()) {
                Some(e) => format!(
                    "**preset: auto**: the recommended settings for this task's form; values \
                     written beside it override them. Here it stands for:\n```hstl\n{e}\n```"
                ),
                None => "**preset: paper** (the default): the paper's settings, Table II of \
                         Li & Belta (2016); `preset: auto` fills in the recommended ones for the \
                         task's form"
                    .to_string(),
            };
            return Some((p.range.clone(), text));
        }
    }
    None
}

/// The text of `r` on one line, its runs of space made one.
pub(crate) fn snippet(text: &str, r: &Range<usize>) -> String {
    text.get(r.clone()).unwrap_or("").split_whitespace().collect::<Vec<_>>().join(" ")
}

fn symbol_hover(a: &Analysis, s: &Symbol) -> Option<String> {
    let spec = a.checked.file.specs.get(s.spec)?;
    let checked = a.checked_spec(s.spec);
    let mut out = String::new();
    match s.kind {
        SymKind::Var => {
            let v = spec.items.iter().find_map(|i| match i {
                Item::State(b) => b.vars.iter().find(|v| v.name.name == s.name),
                _ => None,
            })?;
            let start = v.name.range.start;
            let what = if v.ty == syntax::VarType::Time {
                "time variable (dense time): its trace column holds the time stamps, strictly \
                 increasing; the other variables hold each sample until their next one, and \
                 the intervals are in this column's unit. No formula reads it."
            } else {
                "state variable"
            };
            out.push_str(&format!(
                "```hstl\n{}\n```\n{what}",
                snippet(&a.text, &(start..v.range.end))
            ));
            if let Some(d) = &v.doc {
                out.push_str(&format!("\n\n{}", d.text()));
            }
        }
        SymKind::Let => {
            let l = spec.items.iter().find_map(|i| match i {
                Item::Let(l) if l.name.name == s.name => Some(l),
                _ => None,
            })?;
            out.push_str(&format!(
                "```hstl\nlet {} = {};\n```\n",
                l.name.name,
                snippet(&a.text, &l.formula.range)
            ));
            let info = checked.and_then(|c| c.lets.iter().find(|i| i.name == s.name));
            if let (Some(c), Some(info)) = (checked, info) {
                match info.kind {
                    LetKind::State => out.push_str("state formula (a region)"),
                    LetKind::Temporal => out.push_str("temporal formula"),
                }
                if !info.used {
                    out.push_str(", not used by the task or an option");
                }
                if info.kind == LetKind::State {
                    match count_states(c, &info.formula) {
                        Some(Ok((n, total))) => out.push_str(&format!(
                            "\n\nholds (robustness > 0) in {n} of the {total} states of the declared domain"
                        )),
                        Some(Err(total)) => out.push_str(&format!(
                            "\n\nthe declared domain has {total} states: too many to count where it holds"
                        )),
                        None => {}
                    }
                }
            }
            if let Some(d) = &l.doc {
                out.push_str(&format!("\n\n{}", d.text()));
            }
        }
        SymKind::Option => {
            let o = spec.items.iter().find_map(|i| match i {
                Item::Option(o) if o.name.name == s.name => Some(o),
                _ => None,
            })?;
            out.push_str(&format!("**option {}** (primitive)\n", o.name.name));
            let field = |name: &str| {
                o.fields.as_ref().and_then(|fs| fs.iter().find(|f| f.name.name == name)).map(|f| {
                    match &f.value {
                        FieldValue::Argmax(_) => "argmax".to_string(),
                        FieldValue::Formula(g) => snippet(&a.text, &g.range),
                    }
                })
            };
            let reach = field("reach").unwrap_or_else(|| o.name.name.clone());
            if o.fields.is_none()
                && let Some(l) = spec.items.iter().find_map(|i| match i {
                    Item::Let(l) if l.name.name == o.name.name => Some(l),
                    _ => None,
                })
            {
                out.push_str(&format!(
                    "```hstl\nlet {} = {};\n```\n",
                    l.name.name,
                    snippet(&a.text, &l.formula.range)
                ));
            }
            out.push_str(&format!(
                "- reach: `{reach}` (flat reward: its robustness after each step)\n"
            ));
            // What `preset: auto` filled in, where the option leaves a field out.
            let prim = checked.and_then(|c| c.primitives.iter().find(|p| p.name == s.name));
            let filled_init = prim.is_some_and(|p| {
                matches!(p.init.kind, hstl::lang::CFormulaKind::Not(_)) && field("init").is_none()
            });
            let filled_term = prim.is_some_and(|p| {
                matches!(p.terminate, hstl::lang::Terminate::Formula(_))
                    && field("terminate").is_none()
            });
            match field("init") {
                Some(init) => out.push_str(&format!("- init: `{init}`\n")),
                None if filled_init => out.push_str(&format!(
                    "- init: `!{reach}` (from `preset: auto`: not chosen inside its region)\n"
                )),
                None => out.push_str("- init: `true` (default: may start anywhere)\n"),
            }
            match field("terminate") {
                Some(t) if t != "argmax" => out.push_str(&format!("- terminate: `{t}`\n")),
                None if filled_term => out.push_str(&format!(
                    "- terminate: `{reach}` (from `preset: auto`: stops on entering its region)\n"
                )),
                _ => out.push_str(&format!(
                    "- terminate: `argmax` (where the robustness of `{reach}` is largest over the declared domain)\n"
                )),
            }
            if let Some(c) = checked
                && let Some(p) = c.primitives.iter().position(|p| p.name == s.name)
            {
                if let Some(avoid) = &c.primitives[p].avoid {
                    let text = match field("avoid") {
                        Some(t) => t,
                        None => match &avoid.kind {
                            hstl::lang::CFormulaKind::Let(k) => {
                                c.lets.get(*k).map_or(String::new(), |l| l.name.clone())
                            }
                            _ => "the task's avoided regions (`preset: auto`)".to_string(),
                        },
                    };
                    out.push_str(&format!(
                        "- avoid: `{text}` (the leg's reward also sees its robustness, and the leg stops on entering it)\n"
                    ));
                }
                let seqs: Vec<String> = c
                    .options
                    .iter()
                    .filter(|o| o.sequence.contains(&p))
                    .map(|o| {
                        let legs: Vec<&str> = o
                            .sequence
                            .iter()
                            .filter_map(|&k| c.primitives.get(k))
                            .map(|p| p.name.as_str())
                            .collect();
                        format!("`[{}]`", legs.join(", "))
                    })
                    .collect();
                if seqs.is_empty() {
                    out.push_str("- in no sequence of the options set\n");
                } else {
                    out.push_str(&format!(
                        "- sequences of the options set with it: {}\n",
                        seqs.join(", ")
                    ));
                }
            }
            if let Some(d) = &o.doc {
                out.push_str(&format!("\n{}", d.text()));
            }
        }
    }
    Some(out)
}

/// `(states where f has robustness > 0, states of the domain)`; `Err(total)` when the
/// domain is too large to enumerate; `None` without a finite `int` domain or when `f`
/// cannot be evaluated.
fn count_states(spec: &CheckedSpec, f: &hstl::lang::CFormula) -> Option<Result<(u64, u64), u64>> {
    let total = spec.domain_size()?;
    if total > MAX_DOMAIN_STATES {
        return Some(Err(total));
    }
    if !spec.is_state_formula(f) {
        return None;
    }
    let bounds: Vec<(i64, i64)> = spec
        .state_vars
        .iter()
        .map(|v| match v.domain {
            Domain::Int { lo, hi } => Some((lo, hi)),
            _ => None,
        })
        .collect::<Option<_>>()?;
    let mut ev = StateEvaluator::new(spec, &[f]);
    let mut values: Vec<i64> = bounds.iter().map(|b| b.0).collect();
    let mut s: Vec<f64> = values.iter().map(|&v| v as f64).collect();
    let mut n = 0;
    for _ in 0..total {
        ev.load(&s);
        let r = ev.robustness(f, &s);
        if r.is_nan() {
            return None;
        }
        n += u64::from(r > 0.0);
        // Next valuation, last variable fastest.
        for k in (0..values.len()).rev() {
            if values[k] < bounds[k].1 {
                values[k] += 1;
                s[k] = values[k] as f64;
                break;
            }
            values[k] = bounds[k].0;
            s[k] = values[k] as f64;
        }
    }
    Some(Ok((n, total)))
}

/// The operator whose token(s) cover `offset`, with its hover text.
fn operator_hover(a: &Analysis, offset: usize) -> Option<(Range<usize>, String)> {
    let mut found = None;
    for spec in &a.checked.file.specs {
        let dense = is_dense(spec);
        for item in &spec.items {
            let mut formulas: Vec<&Formula> = Vec::new();
            match item {
                Item::Let(l) => formulas.push(&l.formula),
                Item::Task(t) => formulas.push(&t.formula),
                Item::Option(o) => {
                    for f in o.fields.iter().flatten() {
                        if let FieldValue::Formula(g) = &f.value {
                            formulas.push(g);
                        }
                    }
                }
                _ => {}
            }
            for f in formulas {
                if found.is_none() {
                    found = find_operator(&a.text, f, offset, dense);
                }
            }
        }
    }
    found
}

/// The first operator, in a pre-order walk of `root`, whose token(s) cover `at`. The walk
/// keeps its own stack, so a tall tree cannot overflow the thread's.
fn find_operator(
    text: &str,
    root: &Formula,
    at: usize,
    dense: bool,
) -> Option<(Range<usize>, String)> {
    let mut stack = vec![root];
    while let Some(f) = stack.pop() {
        if at < f.range.start || at > f.range.end {
            continue;
        }
        if let Some(found) = operator_of(text, f, at, dense, &mut stack) {
            return Some(found);
        }
    }
    None
}

/// The operator of `f` itself when its token(s) cover `at`; otherwise pushes the
/// operands onto `stack`, last first.
fn operator_of<'a>(
    text: &str,
    f: &'a Formula,
    at: usize,
    dense: bool,
    stack: &mut Vec<&'a Formula>,
) -> Option<(Range<usize>, String)> {
    let kw_end = |start: usize, kw: &str| start + kw.len();
    let hit = |r: &Range<usize>| r.start <= at && at <= r.end;
    match &f.kind {
        FormulaKind::Always(iv, g)
        | FormulaKind::Eventually(iv, g)
        | FormulaKind::Once(iv, g)
        | FormulaKind::Historically(iv, g) => {
            let (kw, meaning, past) = match f.kind {
                FormulaKind::Always(..) => (
                    "always",
                    "the minimum of the operand's robustness over the window (`+inf` if the window is empty): positive when the operand holds at every step of it",
                    false,
                ),
                FormulaKind::Eventually(..) => (
                    "eventually",
                    "the maximum of the operand's robustness over the window (`-inf` if the window is empty): positive when the operand holds at some step of it",
                    false,
                ),
                FormulaKind::Once(..) => (
                    "once",
                    "the maximum of the operand's robustness over the past window (`-inf` if the window is empty): positive when the operand held at some step of it",
                    true,
                ),
                _ => (
                    "historically",
                    "the minimum of the operand's robustness over the past window (`+inf` if the window is empty): positive when the operand held at every step of it",
                    true,
                ),
            };
            let span =
                f.range.start..iv.as_ref().map_or(kw_end(f.range.start, kw), |i| i.range.end);
            if hit(&span) {
                return Some((
                    span,
                    format!("**{kw}**: {meaning}.\n\n{}", window_words(iv.as_ref(), past, dense)),
                ));
            }
            stack.push(g);
        }
        FormulaKind::Prev(g) | FormulaKind::Next(g) => {
            let prev = matches!(f.kind, FormulaKind::Prev(_));
            let kw = if prev { "prev" } else { "next" };
            let span = f.range.start..kw_end(f.range.start, kw);
            if hit(&span) {
                let meaning = if prev {
                    "**prev**: the operand's robustness one step back; `+inf` at the first step of the trace, which has none (so `prev f` holds there). The same as `historically[1..=1] f`."
                } else {
                    "**next**: the operand's robustness one step ahead; `+inf` at the last step of the trace, which has none (so `next f` holds there). The same as `always[1..=1] f`."
                };
                return Some((span, meaning.to_string()));
            }
            stack.push(g);
        }
        FormulaKind::Until(l, iv, r) | FormulaKind::Since(l, iv, r) => {
            let since = matches!(f.kind, FormulaKind::Since(..));
            let kw = if since { "since" } else { "until" };
            let span = l.range.end..r.range.start;
            if hit(&span) && text.get(span.clone()).is_some_and(|s| s.contains(kw)) {
                let start = span.start + text[span.clone()].find(kw).unwrap_or(0);
                let end = iv.as_ref().map_or(start + kw.len(), |i| i.range.end);
                let meaning = if since {
                    "**since**: `f since[I] g` is the maximum, over the steps `t'` of the past window, of the minimum of `g`'s robustness at `t'` and `f`'s robustness at every step after `t'` up to and including now: positive when `g` held at some step of the window and `f` has held ever since."
                } else {
                    "**until**: `f until[I] g` is the maximum, over the steps `t'` of the window, of the minimum of `g`'s robustness at `t'` and `f`'s robustness at every step from now up to (not including) `t'`: positive when `g` holds at some step of the window and `f` holds until then."
                };
                return Some((
                    start..end,
                    format!("{meaning}\n\n{}", window_words(iv.as_ref(), since, dense)),
                ));
            }
            stack.push(r);
            stack.push(l);
        }
        FormulaKind::And(v) | FormulaKind::Or(v) => {
            let and = matches!(f.kind, FormulaKind::And(_));
            for w in v.windows(2) {
                let span = w[0].range.end..w[1].range.start;
                if hit(&span) {
                    let op = if and { "&&" } else { "||" };
                    let start =
                        span.start + text.get(span.clone()).and_then(|s| s.find(op)).unwrap_or(0);
                    let meaning = if and {
                        "**&&** (and): the minimum of the operands' robustness: positive when every operand holds."
                    } else {
                        "**||** (or): the maximum of the operands' robustness: positive when some operand holds."
                    };
                    return Some((start..start + 2, meaning.to_string()));
                }
            }
            stack.extend(v.iter().rev());
        }
        FormulaKind::Implies(l, r) => {
            let span = l.range.end..r.range.start;
            if hit(&span) {
                let start =
                    span.start + text.get(span.clone()).and_then(|s| s.find("->")).unwrap_or(0);
                return Some((
                    start..start + 2,
                    "**->** (implies): `f -> g` is `!f || g`: the maximum of minus `f`'s robustness and `g`'s robustness.".to_string(),
                ));
            }
            stack.push(r);
            stack.push(l);
        }
        FormulaKind::Not(g) => {
            let span = f.range.start..f.range.start + 1;
            if hit(&span) && at < span.end {
                return Some((span, "**!** (not): minus the operand's robustness.".to_string()));
            }
            stack.push(g);
        }
        FormulaKind::Paren(g) => stack.push(g),
        FormulaKind::Compare { rest, .. } => {
            for (op, r, _) in rest {
                if hit(r) {
                    let meaning = match op {
                        CmpOp::Lt | CmpOp::Le => format!(
                            "**{}**: `e1 {} e2` has robustness `e2 - e1`: how far `e1` is below `e2`.",
                            op.as_str(),
                            op.as_str()
                        ),
                        CmpOp::Gt | CmpOp::Ge => format!(
                            "**{}**: `e1 {} e2` has robustness `e1 - e2`: how far `e1` is above `e2`.",
                            op.as_str(),
                            op.as_str()
                        ),
                        CmpOp::Eq | CmpOp::Ne => format!(
                            "**{}** has no robustness and is rejected; use a band such as `abs(x - 3) < 0.5`.",
                            op.as_str()
                        ),
                    };
                    return Some((r.clone(), meaning));
                }
            }
        }
        FormulaKind::True | FormulaKind::False | FormulaKind::Name(_) => {}
    }
    None
}

/// A time interval in words: a future window (from now on), or a past one (`past`).
/// Whether a spec declares a time variable (`t: time`): a dense-time spec.
fn is_dense(spec: &syntax::Spec) -> bool {
    spec.items.iter().any(|i| match i {
        Item::State(b) => b.vars.iter().any(|v| v.ty == syntax::VarType::Time),
        _ => false,
    })
}

/// A dense-time spec's window in words: times, not steps.
fn dense_window_words(iv: Option<&Interval>, past: bool) -> String {
    let (a, end, inclusive) = match iv {
        None => ("0", None, true),
        Some(iv) => {
            (iv.start.text.as_str(), iv.end.as_ref().map(|e| e.text.as_str()), iv.inclusive)
        }
    };
    let written = iv.map_or("No interval, so `[0..]`".to_string(), |_| match end {
        Some(b) if inclusive => format!("Interval `[{a}..={b}]`"),
        Some(b) => format!("Interval `[{a}..{b}]`"),
        None => format!("Interval `[{a}..]`"),
    });
    let span = match (end, past) {
        (Some(b), false) => format!("the times `t+{a}` to `t+{b}`, both included"),
        (None, false) => format!("every time from `t+{a}` on"),
        (Some(b), true) => format!("the times `t-{b}` to `t-{a}`, both included"),
        (None, true) => format!("every time from the first stamp to `t-{a}`"),
    };
    let edge = if past {
        "clipped at the first time stamp"
    } else {
        "never clipped: after the last stamp every variable keeps its last value"
    };
    format!(
        "Dense time: {written}: the window is {span}, in the time column's unit ({edge}). \
         Each sample holds until its variable's next one."
    )
}

fn window_words(iv: Option<&Interval>, past: bool, dense: bool) -> String {
    if dense {
        return dense_window_words(iv, past);
    }
    let step = |k: u64| step(k, past);
    let Some(iv) = iv else {
        return if past {
            "No interval, so `[0..]`: the window runs from the start of the trace to the current step."
        } else {
            "No interval, so `[0..]`: the window runs from the current step to the end of the trace."
        }
        .to_string();
    };
    let a = iv.start.as_integer();
    let b = iv.end.as_ref().and_then(|e| e.as_integer());
    let (sign, edge) = if past { ('-', "start") } else { ('+', "end") };
    match (a, b, iv.end.is_some(), iv.inclusive) {
        (Some(a), _, false, _) if past => {
            format!(
                "Interval `[{a}..]`: the window runs from the start of the trace to {}.",
                step(a)
            )
        }
        (Some(a), _, false, _) => {
            format!("Interval `[{a}..]`: the window runs from {} to the end of the trace.", step(a))
        }
        (Some(a), Some(b), true, false) if b > a => format!(
            "Interval `[{a}..{b}]`: the window is {} to {} ({} steps; step `t{sign}{b}` excluded), clipped at the {edge} of the trace.",
            step(if past { b - 1 } else { a }),
            step(if past { a } else { b - 1 }),
            b - a
        ),
        (Some(a), Some(b), true, true) if b >= a => format!(
            "Interval `[{a}..={b}]`: the window is {} to {}, both included ({} steps), clipped at the {edge} of the trace.",
            step(if past { b } else { a }),
            step(if past { a } else { b }),
            b - a + 1
        ),
        _ => "The interval is empty or not made of integers (see the diagnostic).".to_string(),
    }
}

/// Step `t+k` (or `t-k` in the past) in words.
fn step(k: u64, past: bool) -> String {
    match (k, past) {
        (0, _) => "the current step `t`".to_string(),
        (_, false) => format!("step `t+{k}`"),
        (_, true) => format!("step `t-{k}`"),
    }
}
