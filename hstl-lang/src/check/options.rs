//! The `options` item: its fields, its sequences and permutations, the `preset: auto`
//! fill-ins and the options set size.

use super::*;

impl Cx<'_> {
    /// Checks the options and builds the set; with `preset: auto`, fills in what the preset
    /// gives. Returns which of `init`, `terminate` and `avoid` it filled in per primitive
    /// (and whether it added the primitive), and whether it chose the options set.
    pub(super) fn options(
        &mut self,
        decls: &[&syntax::OptionDecl],
        item: Option<&syntax::OptionsItem>,
        spec: &syntax::Spec,
        preset: Preset,
        out: &mut CheckedSpec,
    ) -> (Vec<[bool; 4]>, bool) {
        let auto = preset == Preset::Auto;
        let persistent = auto && out.persistent_conjuncts(self.src).is_some();
        let auto_avoid = if auto {
            crate::preset::avoid_formula(&crate::preset::safety_conjuncts(out))
        } else {
            None
        };
        let mut filled: Vec<[bool; 4]> = Vec::new();
        let mut by_name: HashMap<String, (usize, Range<usize>)> = HashMap::new();
        for o in decls {
            if let Some((_, first)) = by_name.get(&o.name.name) {
                let first = first.clone();
                self.push(
                    Diagnostic::new(
                        "HSTL003",
                        o.name.range.clone(),
                        format!("duplicate option `{}`", o.name.name),
                    )
                    .with_label(first, "first declared here")
                    .with_help("rename one of them"),
                );
                continue;
            }
            let mut reach = None;
            let mut init = None;
            let mut terminate = None;
            let mut avoid = None;
            let mut seen: HashMap<String, Range<usize>> = HashMap::new();
            for f in o.fields.iter().flatten() {
                let key = f.name.name.as_str();
                if !OPTION_FIELDS.contains(&key) {
                    let mut d = Diagnostic::new(
                        "HSTL019",
                        f.name.range.clone(),
                        format!("unknown option field `{key}`"),
                    );
                    d = match closest(key, OPTION_FIELDS.into_iter(), &mut u64::MAX.clone()) {
                        Some(c) => d.with_help(format!("did you mean `{c}`?")),
                        None => {
                            d.with_help("an option has `reach`, `init`, `terminate` and `avoid`")
                        }
                    };
                    self.push(d);
                    continue;
                }
                if let Some(first) = seen.get(key) {
                    self.push(
                        Diagnostic::new(
                            "HSTL019",
                            f.name.range.clone(),
                            format!("`{key}` given twice"),
                        )
                        .with_label(first.clone(), "first given here")
                        .with_help("give each field once"),
                    );
                    continue;
                }
                seen.insert(key.to_string(), f.name.range.clone());
                let value = match &f.value {
                    FieldValue::Argmax(_) if key == "terminate" => {
                        terminate = Some(Terminate::Argmax);
                        continue;
                    }
                    FieldValue::Argmax(r) => {
                        self.push(
                            Diagnostic::new(
                                "HSTL008",
                                r.clone(),
                                format!("`argmax` where the `{key}` formula is expected"),
                            )
                            .with_help("`argmax` is only allowed in `terminate`"),
                        );
                        CFormula { kind: CFormulaKind::Invalid, range: r.clone() }
                    }
                    FieldValue::Formula(g) => self.formula(g),
                };
                self.require_state(&value, key, &o.name.name, &out.lets);
                match key {
                    "reach" => reach = Some(value),
                    "init" => init = Some(value),
                    "avoid" => avoid = Some(value),
                    _ => terminate = Some(Terminate::Formula(value)),
                }
            }
            let reach = match reach {
                Some(r) => r,
                None => {
                    let kind = match self.names.get(&o.name.name) {
                        Some((NameRef::Let(j), _)) => CFormulaKind::Let(*j),
                        Some((NameRef::Var(_) | NameRef::Time, def)) => {
                            let def = def.clone();
                            self.push(
                                Diagnostic::new(
                                    "HSTL010",
                                    o.name.range.clone(),
                                    format!(
                                        "option `{}` names a state variable, not a `let`",
                                        o.name.name
                                    ),
                                )
                                .with_label(def, "declared here")
                                .with_help(
                                    "give the option a `reach` field, or name it after a `let`",
                                ),
                            );
                            CFormulaKind::Invalid
                        }
                        None if self.broken_names.contains(&o.name.name) => CFormulaKind::Invalid,
                        None => {
                            let lets = out.lets.iter().map(|l| l.name.as_str());
                            let mut d = Diagnostic::new(
                                "HSTL010",
                                o.name.range.clone(),
                                format!("option `{}` names no `let`", o.name.name),
                            );
                            d = match closest(&o.name.name, lets, &mut self.suggest_budget) {
                                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                                None => d.with_help(format!(
                                    "declare `let {} = ...;` or give the option a `reach` field",
                                    o.name.name
                                )),
                            };
                            self.push(d);
                            CFormulaKind::Invalid
                        }
                    };
                    let f = CFormula { kind, range: o.name.range.clone() };
                    self.require_state(&f, "reach", &o.name.name, &out.lets);
                    f
                }
            };
            by_name.insert(o.name.name.clone(), (out.primitives.len(), o.name.range.clone()));
            // The preset fills in only what was not written: the entry form (`init: !R` on a
            // persistent task, `terminate: R`) and the task's avoided regions.
            let valid = !matches!(reach.kind, CFormulaKind::Invalid);
            let fill = [
                persistent && valid && init.is_none(),
                auto && valid && terminate.is_none(),
                avoid.is_none() && auto_avoid.is_some(),
            ];
            filled.push([fill[0], fill[1], fill[2], false]);
            if fill[0] {
                init = Some(CFormula {
                    kind: CFormulaKind::Not(Box::new(reach.clone())),
                    range: reach.range.clone(),
                });
            }
            if fill[1] {
                terminate = Some(Terminate::Formula(reach.clone()));
            }
            if fill[2] {
                avoid = auto_avoid.clone();
            }
            out.primitives.push(PrimitiveOption {
                name: o.name.name.clone(),
                reach,
                init: init
                    .unwrap_or(CFormula { kind: CFormulaKind::True, range: o.name.range.clone() }),
                terminate: terminate.unwrap_or(Terminate::Argmax),
                avoid,
                doc: doc_text(&o.doc),
                name_range: o.name.range.clone(),
                range: o.range.clone(),
            });
        }
        // HSTL014: options need a bounded state space (tables or tilings cover it).
        if let Some(first) = decls.first() {
            for v in &out.state_vars {
                if v.domain == Domain::Unbounded {
                    let (ty, example) = match v.ty {
                        syntax::VarType::Int => ("int", "int in 0..=N"),
                        syntax::VarType::Float | syntax::VarType::Time => {
                            ("float", "float in LO..=HI")
                        }
                    };
                    self.push(
                        Diagnostic::new(
                            "HSTL014",
                            v.name_range.clone(),
                            format!("state variable `{}` has no bounds", v.name),
                        )
                        .with_label(first.name.range.clone(), "options are declared here")
                        .with_help(format!(
                            "options need a bounded state space: declare `{}: {example}` (it is `{ty}` without a range)",
                            v.name
                        )),
                    );
                }
            }
            // HSTL025: the most robust state of a region is found by enumerating the domain.
            if let Some(v) =
                out.state_vars.iter().find(|v| matches!(v.domain, Domain::Float { .. }))
            {
                for p in out.primitives.iter().filter(|p| p.terminate == Terminate::Argmax) {
                    self.push(
                        Diagnostic::new(
                            "HSTL025",
                            p.name_range.clone(),
                            format!(
                                "option `{}` stops where its region is most robust (`terminate: argmax`, the default), which needs a finite domain, but `{}` is a `float`",
                                p.name, v.name
                            ),
                        )
                        .with_help(format!(
                            "stop on entering the region: `option {} {{ terminate: {} }}`, or `learn {{ preset: auto }}`, which does so",
                            p.name,
                            self.src.get(p.reach.range.clone()).unwrap_or("REGION")
                        )),
                    );
                }
            }
        }
        // The options set.
        let names: Vec<String> = out.primitives.iter().map(|p| p.name.clone()).collect();
        let mut declared: Vec<&str> = names.iter().map(String::as_str).collect();
        declared.sort_unstable();
        let declared_list = some_names(&declared, 10);
        let resolve = |cx: &mut Self, legs: &[syntax::Ident]| -> Option<Vec<usize>> {
            let mut seq: Vec<usize> = Vec::new();
            let mut firsts: HashMap<usize, Range<usize>> = HashMap::new();
            let mut ok = true;
            for leg in legs {
                match by_name.get(&leg.name) {
                    None if cx.broken_names.contains(&leg.name) => ok = false,
                    None => {
                        let mut d = Diagnostic::new(
                            "HSTL011",
                            leg.range.clone(),
                            format!("unknown option `{}`", leg.name),
                        );
                        d = match closest(
                            &leg.name,
                            declared.iter().copied(),
                            &mut cx.suggest_budget,
                        ) {
                            Some(c) => d.with_help(format!("did you mean `{c}`?")),
                            None if declared.is_empty() => {
                                d.with_help(format!("declare it: `option {};`", leg.name))
                            }
                            None => d.with_help(format!("declared options: {declared_list}")),
                        };
                        cx.push(d);
                        ok = false;
                    }
                    Some((i, _)) => {
                        if let Some(first) = firsts.get(i) {
                            cx.push(
                                Diagnostic::new(
                                    "HSTL012",
                                    leg.range.clone(),
                                    format!("option `{}` is repeated", leg.name),
                                )
                                .with_label(first.clone(), "first listed here")
                                .with_help("list each option once"),
                            );
                            ok = false;
                        } else {
                            firsts.insert(*i, leg.range.clone());
                            seq.push(*i);
                        }
                    }
                }
            }
            ok.then_some(seq)
        };
        let mut set: Vec<CombinedOption> = Vec::new();
        let mut set_filled = false;
        let make = |seq: Vec<usize>, range: Range<usize>| CombinedOption {
            name: seq.iter().map(|&i| names[i].as_str()).collect(),
            sequence: seq,
            range,
        };
        match item.map(|i| (&i.kind, i.range.clone())) {
            Some((OptionsKind::List(items), _)) => {
                for s in items {
                    if let Some(seq) = resolve(self, &s.legs) {
                        set.push(make(seq, s.range.clone()));
                    }
                }
            }
            Some((OptionsKind::Sequences(legs), r))
            | Some((OptionsKind::Permutations(legs), r)) => {
                let perm = matches!(item.map(|i| &i.kind), Some(OptionsKind::Permutations(_)));
                if let Some(base) = resolve(self, legs)
                    && self.set_size_ok(base.len(), perm, r.clone())
                {
                    for seq in expand(&base, perm) {
                        set.push(make(seq, r.clone()));
                    }
                }
            }
            None if persistent => {
                // One option per region: with memory the options policy chains them.
                let r = decls.first().map_or(spec.name.range.clone(), |d| d.name.range.clone());
                set_filled = true;
                for i in 0..out.primitives.len() {
                    set.push(make(vec![i], r.clone()));
                }
            }
            None => {
                let base: Vec<usize> = (0..out.primitives.len()).collect();
                let r = decls.first().map_or(spec.name.range.clone(), |d| d.name.range.clone());
                if self.set_size_ok(base.len(), false, r.clone()) {
                    for seq in expand(&base, false) {
                        set.push(make(seq, r.clone()));
                    }
                }
            }
        }
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        for o in set {
            if let Some(first) = seen.get(&o.name) {
                self.push(
                    Diagnostic::new("HSTL013", o.range.clone(), format!("two options named `{}`", o.name))
                        .with_label(first.clone(), "the first one comes from here")
                        .with_help("combined options are named by concatenating their legs: rename a primitive option or drop an entry"),
                );
                continue;
            }
            seen.insert(o.name.clone(), o.range.clone());
            out.options.push(o);
        }
        self.add_keep_clear(auto_avoid, &by_name, &seen, out, &mut filled);
        (filled, set_filled)
    }

    /// With `preset: auto` on a task that keeps out of its avoided regions for good, adds
    /// the primitive and option [`crate::preset::KEEP_CLEAR`] (unless the spec uses the name).
    pub(super) fn add_keep_clear(
        &self,
        avoid: Option<CFormula>,
        primitives: &HashMap<String, (usize, Range<usize>)>,
        options: &HashMap<String, Range<usize>>,
        out: &mut CheckedSpec,
        filled: &mut Vec<[bool; 4]>,
    ) {
        let name = crate::preset::KEEP_CLEAR;
        let Some(avoid) = avoid else { return };
        let taken = primitives.contains_key(name)
            || options.contains_key(name)
            || out.lets.iter().any(|l| l.name == name);
        if taken || out.primitives.is_empty() || !crate::preset::keeps_clear_for_good(out, self.src)
        {
            return;
        }
        // Named where its reason is: the first avoidance for good.
        let range = crate::preset::safety_conjuncts(out)
            .first()
            .map_or(avoid.range.clone(), |c| c.conjunct.range.clone());
        out.primitives.push(PrimitiveOption {
            name: name.to_string(),
            reach: CFormula { kind: CFormulaKind::Not(Box::new(avoid.clone())), range: avoid.range.clone() },
            init: CFormula { kind: CFormulaKind::True, range: range.clone() },
            terminate: Terminate::Argmax,
            avoid: Some(avoid),
            doc: Some("Added by `preset: auto`: once the goals are met, keep clear of the avoided regions.".to_string()),
            name_range: range.clone(),
            range: range.clone(),
        });
        filled.push([false, false, true, true]);
        let leg = out.primitives.len() - 1;
        out.options.push(CombinedOption { name: name.to_string(), sequence: vec![leg], range });
    }

    pub(super) fn set_size_ok(&mut self, n: usize, perm: bool, range: Range<usize>) -> bool {
        let size = set_size(n, perm);
        if size > MAX_OPTIONS {
            let what = if perm { "permutations" } else { "sequences" };
            self.push(
                Diagnostic::new(
                    "HSTL023",
                    range,
                    format!(
                        "`{what}` of {n} options gives {} options, more than {}",
                        thousands(size),
                        thousands(MAX_OPTIONS)
                    ),
                )
                .with_help("list the sequences you need: `options { A, [A, B], ... }`"),
            );
            return false;
        }
        true
    }
}

/// Number of options `sequences` (2^n - 1) or `permutations` (sum of n!/(n-k)!) gives,
/// saturating.
pub(super) fn set_size(n: usize, perm: bool) -> u64 {
    if !perm {
        return if n >= 63 { u64::MAX } else { (1u64 << n) - 1 };
    }
    let mut total: u64 = 0;
    let mut term: u64 = 1;
    for k in 0..n {
        term = term.saturating_mul((n - k) as u64);
        total = total.saturating_add(term);
    }
    total
}

/// Expands `sequences` (subsequences in listed order) or `permutations` (orderings of
/// subsets), by size and then lexicographic order of positions.
pub fn expand(base: &[usize], perm: bool) -> Vec<Vec<usize>> {
    let n = base.len();
    let mut out = Vec::new();
    for size in 1..=n {
        let mut found: Vec<Vec<usize>> = Vec::new();
        let mut cur: Vec<usize> = Vec::new();
        let mut used = vec![false; n];
        gen_positions(n, size, perm, &mut cur, &mut used, &mut found);
        out.extend(found.into_iter().map(|pos| pos.into_iter().map(|p| base[p]).collect()));
    }
    out
}

pub(super) fn gen_positions(
    n: usize,
    size: usize,
    perm: bool,
    cur: &mut Vec<usize>,
    used: &mut [bool],
    out: &mut Vec<Vec<usize>>,
) {
    if cur.len() == size {
        out.push(cur.clone());
        return;
    }
    let from = if perm { 0 } else { cur.last().map_or(0, |&l| l + 1) };
    for p in from..n {
        if used[p] {
            continue;
        }
        used[p] = true;
        cur.push(p);
        gen_positions(n, size, perm, cur, used, out);
        cur.pop();
        used[p] = false;
    }
}
