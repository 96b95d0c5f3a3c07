//! The `learn` item: its parameters (tiles, Q-learning groups, counterfactual, plan) and
//! the checks that need the whole spec (persistent tasks, unseen safety, used names).

use super::*;

impl Cx<'_> {
    pub(super) fn learn(&mut self, l: &syntax::Learn, preset: Preset, out: &mut CheckedSpec) {
        const TOP: [&str; 13] = [
            "preset",
            "episodes",
            "choices",
            "max_steps",
            "memory",
            "intra",
            "reward",
            "counterfactual",
            "switch",
            "plan",
            "flat",
            "options",
            "tiles",
        ];
        if preset == Preset::Auto {
            // The preset first: every value written beside it overrides it.
            let horizons: Option<Vec<u64>> =
                out.persistent_conjuncts(self.src).map(|cs| cs.iter().map(|c| c.steps).collect());
            out.learn.preset = Preset::Auto;
            let reach = crate::preset::is_reach_task(out);
            crate::preset::learn(horizons.as_deref(), reach, out.is_continuous(), &mut out.learn);
            // The memory the preset sizes from the deadlines, made coarser until the runs
            // fit the memory budget without the note of HSTL180.
            // A continuous spec's learned function is counted over the spec's own tile box
            // (the checked spec is the same whatever the world; `check` against a world
            // counts that world's tiles and actions).
            // `note`: above the note of HSTL180 too, not only the budget.
            let over = |out: &CheckedSpec, note: bool| {
                let too_big = |c: crate::budget::Cost| {
                    c.peak().0 > crate::budget::MEMORY_BUDGET
                        || (note && c.own().0 > crate::budget::MEMORY_NOTE)
                };
                if out.is_continuous() {
                    return crate::budget::approx_spec_sizes(self.src, out, None, None)
                        .is_some_and(|s| {
                            crate::budget::approx_weights(&s) > crate::budget::MAX_WEIGHTS
                                || too_big(crate::budget::approx_cost(&s))
                        });
                }
                crate::budget::spec_sizes(self.src, out)
                    .map(|s| crate::budget::cost(&s))
                    .is_some_and(too_big)
            };
            while out.learn.memory > 1 && over(out, true) {
                out.learn.memory -= 1;
            }
            // Past the budget with even one bucket a region (a large world, many regions):
            // no memory, so that the preset never fails the check on its own choice (the
            // window reward still scores the options; `plan: model` needs the memory and is
            // left out).
            if out.learn.memory == 1 && over(out, false) {
                out.learn.memory = 0;
            }
        }
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        for p in &l.params {
            let key = p.name.name.as_str();
            if !self.param_name_ok(p, &TOP, &mut seen) {
                continue;
            }
            match key {
                // Read before the options (`preset_of`); checked here.
                "preset" => {
                    self.word(p, &["paper", "auto"]);
                }
                "counterfactual" => {
                    if let Some(v) = self.whole(p, 0) {
                        if v > MAX_COUNTERFACTUAL {
                            self.push(
                                Diagnostic::new(
                                    "HSTL016",
                                    value_range(&p.value),
                                    format!("`counterfactual` must be at most {MAX_COUNTERFACTUAL}, found {v}"),
                                )
                                .with_help("a few memory values per option execution are enough, such as `counterfactual: 8`"),
                            );
                        } else {
                            out.learn.counterfactual = v;
                        }
                    }
                }
                "episodes" | "choices" | "max_steps" | "memory" => {
                    let min = if key == "memory" { 0 } else { 1 };
                    if let Some(v) = self.whole(p, min) {
                        match key {
                            "episodes" => out.learn.episodes = v,
                            "choices" => out.learn.choices = v,
                            "max_steps" => out.learn.max_steps = v,
                            _ => out.learn.memory = v,
                        }
                    }
                }
                "intra" => match self.word(p, &["paper", "remaining"]).as_deref() {
                    Some("paper") => out.learn.intra = Intra::Paper,
                    Some(_) => out.learn.intra = Intra::Remaining,
                    None => {}
                },
                "switch" => match self.word(p, &["termination", "step"]).as_deref() {
                    Some("termination") => out.learn.switch = Switch::Termination,
                    Some(_) => out.learn.switch = Switch::Step,
                    None => {}
                },
                "plan" => match self.word(p, &["off", "model"]).as_deref() {
                    Some("off") => out.learn.plan = Plan::Off,
                    Some(_) => out.learn.plan = Plan::Model,
                    None => {}
                },
                "reward" => match self.word(p, &["segment", "window"]).as_deref() {
                    Some("segment") => out.learn.reward = Reward::Segment,
                    Some(_) => out.learn.reward = Reward::Window,
                    None => {}
                },
                _ => {
                    let ParamValue::Group(ps, _) = &p.value else {
                        self.push(
                            Diagnostic::new(
                                "HSTL016",
                                value_range(&p.value),
                                format!("`{key}` takes a group of parameters"),
                            )
                            .with_help(format!("write `{key}: {{ gamma: 0.9, alpha: 0.5 }}`")),
                        );
                        continue;
                    };
                    if key == "tiles" {
                        let mut t = out.learn.tiles.unwrap_or_default();
                        self.tiles(ps, &mut t);
                        out.learn.tiles = Some(t);
                        continue;
                    }
                    let mut q = if key == "flat" { out.learn.flat } else { out.learn.options };
                    self.qparams(ps, key, &mut q);
                    if key == "flat" { out.learn.flat = q } else { out.learn.options = q }
                }
            }
        }
    }

    /// HSTL071: counterfactual updates replay the memory's counters and the window reward:
    /// they need both.
    pub(super) fn counterfactual_needs(&mut self, l: &syntax::Learn, out: &CheckedSpec) {
        let learn = &out.learn;
        if learn.counterfactual == 0 || (learn.memory > 0 && learn.reward == Reward::Window) {
            return;
        }
        let Some(p) = l.params.iter().find(|p| p.name.name == "counterfactual") else { return };
        let missing = match (learn.memory > 0, learn.reward == Reward::Window) {
            (false, false) => "`memory` and `reward: window`",
            (false, true) => "`memory`",
            _ => "`reward: window`",
        };
        self.push(
            Diagnostic::new(
                "HSTL071",
                p.range.clone(),
                format!("`counterfactual` needs {missing}"),
            )
            .with_help("counterfactual updates replay the memory's counters along each option's run and score it by the window reward: add `memory: 8, reward: window`, or write `learn { preset: auto }` on a persistent task"),
        );
    }

    /// HSTL072: `plan: model` plans the options level of a persistent task over the
    /// memory's counters, one option per region: a spec of another shape is refused where
    /// it writes `plan: model`, and left to Q-learning where only the preset asked for it.
    pub(super) fn plan_needs(&mut self, l: &syntax::Learn, out: &mut CheckedSpec) {
        if out.learn.plan != Plan::Model {
            return;
        }
        let Some(missing) = plan_missing(out, self.src) else { return };
        match l.params.iter().find(|p| p.name.name == "plan") {
            Some(p) => self.push(
                Diagnostic::new("HSTL072", p.range.clone(), format!("`plan: model` needs {missing}"))
                    .with_help("planning values the options of a persistent task `always[0..] (eventually[0..N] A && ...)` over the memory's counters: write `learn { preset: auto }` with `option A;` per region, or remove `plan: model`"),
            ),
            None => out.learn.plan = Plan::Off,
        }
    }

    pub(super) fn param_name_ok(
        &mut self,
        p: &syntax::Param,
        known: &[&str],
        seen: &mut HashMap<String, Range<usize>>,
    ) -> bool {
        let key = p.name.name.as_str();
        if !known.contains(&key) {
            let mut d = Diagnostic::new(
                "HSTL019",
                p.name.range.clone(),
                format!("unknown parameter `{key}`"),
            );
            d = match closest(key, known.iter().copied(), &mut u64::MAX.clone()) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!("known parameters: {}", known.join(", "))),
            };
            self.push(d);
            return false;
        }
        if let Some(first) = seen.get(key) {
            self.push(
                Diagnostic::new(
                    "HSTL019",
                    p.name.range.clone(),
                    format!("parameter `{key}` given twice"),
                )
                .with_label(first.clone(), "first given here")
                .with_help("give each parameter once"),
            );
            return false;
        }
        seen.insert(key.to_string(), p.name.range.clone());
        true
    }

    pub(super) fn whole(&mut self, p: &syntax::Param, min: u64) -> Option<u64> {
        let key = &p.name.name;
        let cond = if min == 0 { ">= 0" } else { "> 0" };
        match &p.value {
            ParamValue::Number(n) => match n.as_integer() {
                Some(v) if v >= min => Some(v),
                _ => {
                    self.push(
                        Diagnostic::new(
                            "HSTL016",
                            n.range.clone(),
                            format!("`{key}` must be a whole number {cond}, found `{}`", n.text),
                        )
                        .with_help(format!(
                            "write a whole number {cond}, such as `{}`",
                            min.max(1) * 100
                        )),
                    );
                    None
                }
            },
            v => {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        value_range(v),
                        format!("`{key}` must be a whole number {cond}"),
                    )
                    .with_help(format!("write a number, such as `{key}: {}`", min.max(1) * 100)),
                );
                None
            }
        }
    }

    pub(super) fn word(&mut self, p: &syntax::Param, allowed: &[&str]) -> Option<String> {
        let key = &p.name.name;
        let options = format!("`{}` or `{}`", allowed[0], allowed[1]);
        match &p.value {
            ParamValue::Word(w) if allowed.contains(&w.name.as_str()) => Some(w.name.clone()),
            v => {
                let mut d = Diagnostic::new(
                    "HSTL016",
                    value_range(v),
                    format!("`{key}` must be {options}, found `{}`", self.text(&value_range(v))),
                );
                d = match v {
                    ParamValue::Word(w) => {
                        match closest(&w.name, allowed.iter().copied(), &mut u64::MAX.clone()) {
                            Some(c) => d.with_help(format!("did you mean `{c}`?")),
                            None => d.with_help(format!("write {options}")),
                        }
                    }
                    _ => d.with_help(format!("write {options}")),
                };
                self.push(d);
                None
            }
        }
    }

    /// `tiles: { tilings: N, bins: N }`.
    pub(super) fn tiles(&mut self, ps: &[syntax::Param], t: &mut Tiles) {
        const KNOWN: [&str; 2] = ["tilings", "bins"];
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        for p in ps {
            if !self.param_name_ok(p, &KNOWN, &mut seen) {
                continue;
            }
            let (key, max) = if p.name.name == "tilings" {
                ("tilings", MAX_TILINGS)
            } else {
                ("bins", MAX_TILE_BINS)
            };
            let Some(v) = self.whole(p, 1) else { continue };
            if v > max {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        value_range(&p.value),
                        format!("`tiles.{key}` must be at most {max}, found {v}"),
                    )
                    .with_help(if key == "tilings" {
                        "8 tilings are the usual choice".to_string()
                    } else {
                        "tiles about one world step wide are the usual choice".to_string()
                    }),
                );
                continue;
            }
            if key == "tilings" {
                t.tilings = v;
            } else {
                t.bins = Some(v);
            }
        }
    }

    pub(super) fn qparams(&mut self, ps: &[syntax::Param], group: &str, q: &mut QParams) {
        const KNOWN: [&str; 5] = ["gamma", "alpha", "epsilon", "min_epsilon", "decay"];
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        let mut ranges: HashMap<&str, Range<usize>> = HashMap::new();
        for p in ps {
            if !self.param_name_ok(p, &KNOWN, &mut seen) {
                continue;
            }
            let key = p.name.name.as_str();
            let ParamValue::Number(n) = &p.value else {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        value_range(&p.value),
                        format!("`{group}.{key}` must be a number"),
                    )
                    .with_help("write a number, such as `0.9`"),
                );
                continue;
            };
            let v = n.value;
            let (ok, cond) = match key {
                "gamma" | "alpha" => (v > 0.0 && v <= 1.0, "in (0, 1]"),
                "epsilon" | "min_epsilon" => ((0.0..=1.0).contains(&v), "in [0, 1]"),
                _ => (v >= 0.0 && v.is_finite(), ">= 0"),
            };
            if !ok {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        n.range.clone(),
                        format!("`{group}.{key}` must be {cond}, found `{}`", n.text),
                    )
                    .with_help(format!("choose a value {cond}")),
                );
                continue;
            }
            let k = KNOWN.iter().copied().find(|k| *k == key).unwrap_or("decay");
            ranges.insert(k, n.range.clone());
            match key {
                "gamma" => q.gamma = v,
                "alpha" => q.alpha = v,
                "epsilon" => q.epsilon = v,
                "min_epsilon" => q.min_epsilon = v,
                _ => q.decay = v,
            }
        }
        if q.min_epsilon > q.epsilon {
            let r = ranges.get("min_epsilon").or(ranges.get("epsilon")).cloned();
            if let Some(r) = r {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        r,
                        format!(
                            "`{group}.min_epsilon` ({}) exceeds `{group}.epsilon` ({})",
                            q.min_epsilon, q.epsilon
                        ),
                    )
                    .with_help("0 <= min_epsilon <= epsilon <= 1"),
                );
            }
        }
    }

    /// HSTL170: a safety conjunct `always !R` of the task that no option's `avoid` covers:
    /// the legs' reward never sees it, so nothing below the options level keeps out of `R`.
    pub(super) fn safety_unseen(&mut self, out: &CheckedSpec) {
        if out.primitives.is_empty() {
            return;
        }
        for c in crate::preset::safety_conjuncts(out) {
            let seen = out.primitives.iter().any(|p| {
                p.avoid.as_ref().is_some_and(|a| crate::preset::covers(a, c.region, self.src))
            });
            if seen {
                continue;
            }
            let name = match c.region.kind {
                CFormulaKind::Let(i) => out.lets.get(i).map_or(String::new(), |l| l.name.clone()),
                _ => self.src.get(c.region.range.clone()).unwrap_or("").trim().to_string(),
            };
            self.push(
                Diagnostic::new(
                    "HSTL170",
                    c.conjunct.range.clone(),
                    format!(
                        "no option's reward sees the safety conjunct: the legs may enter `{name}`"
                    ),
                )
                .with_help(format!(
                    "give the options `avoid: {name}`, or write `learn {{ preset: auto }}`"
                )),
            );
        }
    }

    pub(super) fn persistent_needs(&mut self, learn: Option<&syntax::Learn>, out: &CheckedSpec) {
        let Some(l) = learn else { return };
        let Some(task) = &out.task else { return };
        if matches!(task.formula.kind, CFormulaKind::Invalid)
            || out.persistent_conjuncts(self.src).is_some()
        {
            return;
        }
        for p in &l.params {
            let needs = match (&p.name.name[..], &p.value) {
                ("memory", ParamValue::Number(n)) => n.as_integer().is_some_and(|v| v > 0),
                ("reward", ParamValue::Word(w)) => w.name == "window",
                _ => false,
            };
            if needs {
                self.push(
                    Diagnostic::new(
                        "HSTL017",
                        p.range.clone(),
                        format!("`{}` needs a persistent task", self.text(&p.range)),
                    )
                    .with_label(task.formula.range.clone(), "this task is not of that form")
                    .with_help("write the task as `always[0..] (eventually[0..N1] R1 && ... && eventually[0..Nk] Rk)` with state formulas Rj"),
                );
            }
        }
    }

    pub(super) fn mark_used(&mut self, out: &mut CheckedSpec) {
        let mut stack: Vec<usize> = Vec::new();
        let push_refs =
            |f: &CFormula, stack: &mut Vec<usize>| visit_lets(f, &mut |i| stack.push(i));
        if let Some(t) = &out.task {
            push_refs(&t.formula, &mut stack);
        }
        for p in &out.primitives {
            push_refs(&p.reach, &mut stack);
            push_refs(&p.init, &mut stack);
            if let Terminate::Formula(f) = &p.terminate {
                push_refs(f, &mut stack);
            }
            if let Some(f) = &p.avoid {
                push_refs(f, &mut stack);
            }
        }
        while let Some(i) = stack.pop() {
            if let Some(l) = out.lets.get_mut(i)
                && !l.used
            {
                l.used = true;
                let f = l.formula.clone();
                push_refs(&f, &mut stack);
            }
        }
    }
}

pub(super) fn value_range(v: &ParamValue) -> Range<usize> {
    match v {
        ParamValue::Number(n) => n.range.clone(),
        ParamValue::Word(w) => w.range.clone(),
        ParamValue::Group(_, r) => r.clone(),
    }
}

/// What a spec lacks for `plan: model`, or `None` when it has it all: a persistent task,
/// `memory`, `reward: window`, an options gamma below 1, and an options set of one option
/// per region, each a single leg that stops on entering its region (no `avoid`).
pub(super) fn plan_missing(out: &CheckedSpec, src: &str) -> Option<&'static str> {
    let Some(regions) = out.persistent_conjuncts(src) else {
        // A reach task: its legs are planned, whatever the options.
        if crate::preset::is_reach_task(out) && !out.is_continuous() {
            return None;
        }
        return Some(
            "a persistent task `always[0..] (eventually[0..N] A && ...)` or a reach task \
             `eventually[0..T] G && always !R`",
        );
    };
    if regions.iter().any(|r| r.safety) {
        return Some("a task without safety conjuncts `always !R` (the legs avoid them instead)");
    }
    let l = &out.learn;
    if l.memory == 0 {
        return Some("`memory`");
    }
    if l.reward != Reward::Window {
        return Some("`reward: window`");
    }
    if l.options.gamma >= 1.0 {
        return Some("an options gamma below 1");
    }
    let enters_a_region = |o: &CombinedOption| -> bool {
        let [p] = o.sequence.as_slice() else { return false };
        let Some(p) = out.primitives.get(*p) else { return false };
        let Terminate::Formula(t) = &p.terminate else { return false };
        p.avoid.is_none() && regions.iter().any(|r| crate::preset::covers(t, &r.region, src))
    };
    if out.options.is_empty() || !out.options.iter().all(enters_a_region) {
        return Some("options of one leg each that stop on entering a region of the task");
    }
    None
}
