//! The finite-domain pass: enumerates the declared `int` domain to find empty and full
//! regions, states where no option can start and gaps inside sequences, on up to four
//! threads with the same diagnostics as on one.

use super::*;

impl Cx<'_> {
    /// The checks that enumerate the declared `int` domain: empty and full regions,
    /// states where no option can start, and gaps inside sequences.
    // `k` numbers a state and indexes several per-option tables at once.
    #[allow(clippy::needless_range_loop)]
    pub(super) fn finite_domain(
        &mut self,
        out: &CheckedSpec,
        item: Option<&syntax::OptionsItem>,
        spec: &syntax::Spec,
        mask: Option<&DomainMask>,
        plan_written: bool,
    ) -> bool {
        // Where the domain is not counted, the preset cannot know that planning fits: it
        // Q-learns (a `plan: model` written out is left to the runtime's own limits).
        let preset_plans = out.learn.plan == Plan::Model && !plan_written;
        let Some(size) = out.domain_size() else { return preset_plans };
        if out.state_vars.is_empty() {
            return preset_plans;
        }
        if size > MAX_DOMAIN_STATES {
            self.domain_skipped(
                out,
                format!(
                    "the domain has {} states, more than the {} the finite-domain checks \
                     enumerate; they are skipped",
                    thousands(size),
                    thousands(MAX_DOMAIN_STATES)
                ),
                "shrink the `int` ranges to get the region and option checks",
            );
            return preset_plans;
        }
        // Regions: lets an option reaches, and the Rj of a persistent task.
        let mut regions: Vec<(CFormula, Range<usize>, String)> = Vec::new();
        let add_region = |f: &CFormula, regions: &mut Vec<(CFormula, Range<usize>, String)>| {
            if !out.is_state_formula(f) {
                return;
            }
            let (range, name) = match f.kind {
                CFormulaKind::Let(i) => (out.lets[i].name_range.clone(), out.lets[i].name.clone()),
                _ => (f.range.clone(), self.src.get(f.range.clone()).unwrap_or("").to_string()),
            };
            if !regions.iter().any(|(_, r, _)| *r == range) {
                regions.push((f.clone(), range, name));
            }
        };
        for p in &out.primitives {
            add_region(&p.reach, &mut regions);
        }
        // The regions before this index are reached by an option.
        let reached = regions.len();
        // A safety conjunct's `!S` is no region to visit: `S` is checked as written.
        for c in out.persistent_conjuncts(self.src).unwrap_or_default() {
            if !c.safety {
                add_region(&c.region, &mut regions);
            }
        }
        let present = |k: usize| mask.is_none_or(|m| m.present[k]);
        let np = out.primitives.len();
        let mut roots: Vec<&CFormula> = regions.iter().map(|(f, _, _)| f).collect();
        for p in &out.primitives {
            roots.push(&p.reach);
            roots.push(&p.init);
            if let Terminate::Formula(f) = &p.terminate {
                roots.push(f);
            }
            if let Some(f) = &p.avoid {
                roots.push(f);
            }
        }
        let ev = StateEvaluator::new(out, &roots);
        // Bound the time spent: each state evaluates the lets the regions need.
        let work = size.saturating_mul((ev.needed_lets() + roots.len()) as u64);
        if work > MAX_DOMAIN_WORK {
            self.domain_skipped(
                out,
                format!(
                    "the finite-domain checks would evaluate {} formulas ({} states, {} lets), \
                     more than {}; they are skipped",
                    thousands(work),
                    thousands(size),
                    ev.needed_lets(),
                    thousands(MAX_DOMAIN_WORK)
                ),
                "shrink the `int` ranges, or shorten the chains of lets the regions use",
            );
            return preset_plans;
        }
        let n = size as usize;
        let states = |k: usize| -> Vec<f64> {
            let mut s = vec![0.0; out.state_vars.len()];
            let mut rest = k;
            for (j, v) in out.state_vars.iter().enumerate().rev() {
                if let Domain::Int { lo, hi } = v.domain {
                    let w = (hi - lo + 1) as usize;
                    s[j] = (lo + (rest % w) as i64) as f64;
                    rest /= w;
                }
            }
            s
        };
        // Pass 1: region counts and the maximum robustness of each reach. States are
        // independent: large domains are split into contiguous chunks run on several
        // threads, merged in state order (the same counts, maxima and sets). The preset's
        // choice to plan is made on the map without its walls, so that the macro (which
        // sees no world) and the CLI (which does) choose alike.
        let count_walls = preset_plans && mask.is_some();
        let chunks = over_states(out, &roots, n, work, |ev, ks| {
            let mut region_sat = vec![0u64; regions.len()];
            let mut region_walls = vec![0u64; regions.len()];
            let mut region_reachable = vec![0u64; regions.len()];
            let mut reach_max = vec![f64::NEG_INFINITY; np];
            let mut init_set = vec![Vec::with_capacity(ks.len()); np];
            for k in ks {
                if !present(k) {
                    // A wall: no state, so in no set.
                    init_set.iter_mut().for_each(|set| set.push(false));
                    if count_walls {
                        let s = states(k);
                        ev.load(&s);
                        for (r, (f, _, _)) in regions.iter().enumerate() {
                            region_walls[r] += u64::from(ev.robustness(f, &s) > 0.0);
                        }
                    }
                    continue;
                }
                let s = states(k);
                ev.load(&s);
                let reachable = mask.is_none_or(|m| m.reachable[k]);
                for (r, (f, _, _)) in regions.iter().enumerate() {
                    if ev.robustness(f, &s) > 0.0 {
                        region_sat[r] += 1;
                        region_reachable[r] += u64::from(reachable);
                    }
                }
                for (p, prim) in out.primitives.iter().enumerate() {
                    let v = ev.robustness(&prim.reach, &s);
                    if v > reach_max[p] {
                        reach_max[p] = v;
                    }
                    init_set[p].push(ev.robustness(&prim.init, &s) > 0.0);
                }
            }
            (region_sat, region_walls, region_reachable, reach_max, init_set)
        });
        let mut region_sat = vec![0u64; regions.len()];
        let mut region_walls = vec![0u64; regions.len()];
        let mut region_reachable = vec![0u64; regions.len()];
        let mut reach_max = vec![f64::NEG_INFINITY; np];
        let mut init_set: Vec<Vec<bool>> = vec![Vec::with_capacity(n); np];
        for (sat, walls, reachable, max, init) in chunks {
            for (total, c) in region_sat.iter_mut().zip(sat) {
                *total += c;
            }
            for (total, c) in region_walls.iter_mut().zip(walls) {
                *total += c;
            }
            for (total, c) in region_reachable.iter_mut().zip(reachable) {
                *total += c;
            }
            // Chunks in state order, and only a larger value replaces: the first maximum.
            for (m, v) in reach_max.iter_mut().zip(max) {
                if v > *m {
                    *m = v;
                }
            }
            for (set, part) in init_set.iter_mut().zip(init) {
                set.extend(part);
            }
        }
        let size_without_walls = size;
        let size = match mask {
            Some(m) => m.present.iter().filter(|&&p| p).count() as u64,
            None => size,
        };
        let mut plan_too_large = false;
        if out.learn.plan == Plan::Model
            && let (Some(conjuncts), Some(task)) = (out.persistent_conjuncts(self.src), &out.task)
        {
            let range_of = |f: &CFormula| match f.kind {
                CFormulaKind::Let(i) => out.lets[i].name_range.clone(),
                _ => f.range.clone(),
            };
            // Region cells under walls are counted only for the preset (zero otherwise).
            let cells: Vec<u64> = conjuncts
                .iter()
                .map(|c| {
                    let r = range_of(&c.region);
                    let at = regions.iter().position(|(_, at, _)| *at == r);
                    at.map_or(0, |i| region_sat[i] + region_walls[i])
                })
                .collect();
            let states = if preset_plans { size_without_walls } else { size };
            let horizons: Vec<u64> = conjuncts.iter().map(|c| c.steps).collect();
            let l = &out.learn;
            let options = out.options.len() as u64;
            let exceeded =
                budget::plan_exceeded(states, &cells, &horizons, options, l.memory, l.max_steps);
            if preset_plans {
                // The preset plans only what takes a fraction of a second. The sizes grow
                // with the walls counted in, so what it plans fits the map with them too.
                plan_too_large = exceeded.is_some()
                    || budget::plan_time(states, &cells, &horizons, options, l.memory)
                        > budget::PRESET_PLAN_WORK;
            } else if let Some(why) = exceeded {
                self.push(
                    Diagnostic::new("HSTL033", task.formula.range.clone(), why).with_help(
                        "use smaller or fewer regions, or shorter windows, or write `plan: off` to Q-learn the options level",
                    ),
                );
            }
        }
        let world = self.world.filter(|_| mask.is_some());
        for (r, (_, range, name)) in regions.iter().enumerate() {
            if let Some(world) = world
                && region_sat[r] == 0
            {
                let (code, what) = if r < reached {
                    ("HSTL031", "an option reaches it, so the option cannot succeed")
                } else {
                    ("HSTL102", "the task cannot be kept")
                };
                self.push(
                    Diagnostic::new(
                        code,
                        range.clone(),
                        format!(
                            "no free cell of {} satisfies region `{name}`: {what}",
                            world.label
                        ),
                    )
                    .with_help(
                        "check the bounds against the map: walls are not cells the robot can be in",
                    ),
                );
            } else if let Some(world) = world
                && region_reachable[r] == 0
            {
                self.push(
                    Diagnostic::new(
                        "HSTL131",
                        range.clone(),
                        format!("no start of {} can reach region `{name}`: walls cut it off", world.label),
                    )
                    .with_help("open a way through the walls, add a start cell (`S`) on its side, or move the region"),
                );
            } else if region_sat[r] == 0 {
                self.push(
                    Diagnostic::new(
                        "HSTL102",
                        range.clone(),
                        format!("no state of the domain satisfies region `{name}`"),
                    )
                    .with_help("check the bounds against the `int` ranges (on integers, `3 < x < 4` is empty)"),
                );
            } else if region_sat[r] == size {
                self.push(
                    Diagnostic::new(
                        "HSTL103",
                        range.clone(),
                        format!("every state of the domain satisfies region `{name}`"),
                    )
                    .with_help("tighten the formula: reaching it needs no learning"),
                );
            }
        }
        if out.options.is_empty() {
            return plan_too_large;
        }
        // Pass 2: termination sets.
        // With them, per primitive, the termination states outside its avoided region.
        let chunks = over_states(out, &roots, n, work, |ev, ks| {
            let mut term_set = vec![Vec::with_capacity(ks.len()); np];
            let mut safe_stops = vec![0u64; np];
            for k in ks {
                if !present(k) {
                    term_set.iter_mut().for_each(|set| set.push(false));
                    continue;
                }
                let s = states(k);
                ev.load(&s);
                for (p, prim) in out.primitives.iter().enumerate() {
                    let stops = match &prim.terminate {
                        Terminate::Argmax => ev.robustness(&prim.reach, &s) == reach_max[p],
                        Terminate::Formula(f) => ev.robustness(f, &s) > 0.0,
                    };
                    term_set[p].push(stops);
                    let avoided = prim.avoid.as_ref().is_some_and(|a| ev.robustness(a, &s) >= 0.0);
                    safe_stops[p] += u64::from(stops && !avoided);
                }
            }
            (term_set, safe_stops)
        });
        let mut term_set: Vec<Vec<bool>> = vec![Vec::with_capacity(n); np];
        let mut safe_stops = vec![0u64; np];
        for (chunk, safe) in chunks {
            for (set, part) in term_set.iter_mut().zip(chunk) {
                set.extend(part);
            }
            for (total, c) in safe_stops.iter_mut().zip(safe) {
                *total += c;
            }
        }
        // HSTL070: every state where a leg stops lies in the region it avoids.
        for (p, prim) in out.primitives.iter().enumerate() {
            if let Some(a) = &prim.avoid
                && safe_stops[p] == 0
                && term_set[p].iter().any(|&t| t)
            {
                self.push(
                    Diagnostic::new(
                        "HSTL070",
                        a.range.clone(),
                        format!(
                            "option `{}` avoids every state where it stops: it cannot succeed without entering its `avoid` region",
                            prim.name
                        ),
                    )
                    .with_label(prim.name_range.clone(), format!("`{}` is declared here", prim.name))
                    .with_help("narrow the `avoid` region, or move the option's region out of it"),
                );
            }
        }
        // HSTL032: a termination set with no state (argmax sets never are empty).
        for (p, prim) in out.primitives.iter().enumerate() {
            if let Terminate::Formula(f) = &prim.terminate
                && !term_set[p].iter().any(|&t| t)
            {
                let place = world.map_or("state of the domain".to_string(), |w| {
                    format!("free cell of {}", w.label)
                });
                self.push(
                    Diagnostic::new(
                        "HSTL032",
                        f.range.clone(),
                        format!("option `{}` can never stop: no {place} satisfies its `terminate`", prim.name),
                    )
                    .with_label(prim.name_range.clone(), format!("`{}` is declared here", prim.name))
                    .with_help("widen the `terminate` formula, or leave it out to stop where the region is most robust"),
                );
            }
        }
        // HSTL018: states where no option of the set can start.
        let firsts: Vec<usize> =
            out.options.iter().filter_map(|o| o.sequence.first().copied()).collect();
        let stuck: Vec<usize> =
            (0..n).filter(|&k| present(k) && !firsts.iter().any(|&p| init_set[p][k])).collect();
        if let Some(&k) = stuck.first() {
            let r = item.map_or(spec.name.range.clone(), |i| i.range.clone());
            self.push(
                Diagnostic::new(
                    "HSTL018",
                    r,
                    format!(
                        "no option of the set can start in {}, such as {}",
                        plural(stuck.len() as u64, "state", "states"),
                        state_text(&out.state_vars, &states(k))
                    ),
                )
                .with_help("widen an option's `init`, or add an option that can start there"),
            );
        }
        // HSTL020: a leg that can terminate outside the next leg's initiation set.
        let mut reported: Vec<(usize, usize)> = Vec::new();
        for o in &out.options {
            for w in o.sequence.windows(2) {
                let (a, b) = (w[0], w[1]);
                if reported.contains(&(a, b)) {
                    continue;
                }
                let bad: Vec<usize> =
                    (0..n).filter(|&k| term_set[a][k] && !init_set[b][k]).collect();
                if let Some(&k) = bad.first() {
                    reported.push((a, b));
                    let (pa, pb) = (&out.primitives[a], &out.primitives[b]);
                    self.push(
                        Diagnostic::new(
                            "HSTL020",
                            o.range.clone(),
                            format!(
                                "in `{}`, `{}` can terminate in {} where `{}` cannot start, such as {}",
                                o.name,
                                pa.name,
                                plural(bad.len() as u64, "state", "states"),
                                pb.name,
                                state_text(&out.state_vars, &states(k))
                            ),
                        )
                        .with_label(pa.name_range.clone(), format!("`{}` is declared here", pa.name))
                        .with_label(pb.init.range.clone(), format!("`{}` can start only where this holds", pb.name))
                        .with_help(format!("widen the `init` of `{}` or narrow the `terminate` of `{}`", pb.name, pa.name)),
                    );
                }
            }
        }
        plan_too_large
    }

    /// HSTL022 at the state block: the finite-domain checks are skipped, `message` says
    /// why and `help` how to get them.
    fn domain_skipped(&mut self, out: &CheckedSpec, message: String, help: &str) {
        let r = out.state_vars[0].range.start..out.state_vars[out.state_vars.len() - 1].range.end;
        self.push(Diagnostic::new("HSTL022", r, message).with_help(help));
    }
}

#[cfg(test)]
thread_local! {
    /// Tests set this to run the finite-domain passes on one thread, for comparison.
    static ONE_THREAD: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether a test asked for one thread.
pub(super) fn one_thread() -> bool {
    #[cfg(test)]
    let one = ONE_THREAD.with(std::cell::Cell::get);
    #[cfg(not(test))]
    let one = false;
    one
}

/// Work (states times formulas) from which the finite-domain passes use several threads.
pub(super) const PARALLEL_DOMAIN_WORK: u64 = 100_000;

/// Runs `pass` over the states `0..n` with an evaluator of `roots`: in one piece, or for
/// `work` of at least [`PARALLEL_DOMAIN_WORK`] in contiguous chunks on up to four
/// threads. The results come in state order.
pub(super) fn over_states<T: Send>(
    out: &CheckedSpec,
    roots: &[&CFormula],
    n: usize,
    work: u64,
    pass: impl Fn(&mut StateEvaluator<'_>, Range<usize>) -> T + Sync,
) -> Vec<T> {
    let run = |ks: Range<usize>| pass(&mut StateEvaluator::new(out, roots), ks);
    // Asking for the core count reads files, so small work never asks.
    if work < PARALLEL_DOMAIN_WORK || one_thread() {
        return vec![run(0..n)];
    }
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get()).min(4);
    if threads < 2 || n < threads {
        return vec![run(0..n)];
    }
    let chunk = n.div_ceil(threads);
    let parts: Vec<Range<usize>> = (0..n).step_by(chunk).map(|a| a..(a + chunk).min(n)).collect();
    std::thread::scope(|scope| {
        let run = &run;
        let handles: Vec<_> = parts[1..]
            .iter()
            .map(|ks| {
                let ks = ks.clone();
                (ks.clone(), std::thread::Builder::new().spawn_scoped(scope, move || run(ks)))
            })
            .collect();
        let mut results = vec![run(parts[0].clone())];
        for (ks, spawned) in handles {
            // A thread that could not start (or failed) leaves its chunk to this one.
            match spawned.ok().and_then(|h| h.join().ok()) {
                Some(r) => results.push(r),
                None => results.push(run(ks)),
            }
        }
        results
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fixtures whose finite-domain checks report something, with their domains widened
    /// so that the passes run on several threads: the same diagnostics as on one thread.
    #[test]
    fn domain_passes_on_threads_match_one_thread() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");
        for name in [
            "invalid/HSTL020_sequence_gap.hstl",
            "invalid/HSTL018_no_option_can_start.hstl",
            "invalid/HSTL102_empty_region.hstl",
            "invalid/HSTL103_full_region.hstl",
            "valid/case_study_ot1.hstl",
        ] {
            let text = std::fs::read_to_string(format!("{dir}/{name}")).unwrap_or_default();
            assert!(text.contains("0..=14") || text.contains("0..=9"), "{name}");
            let wide = text.replace("0..=14", "0..=239").replace("0..=9", "0..=239");
            let threads = check(&wide);
            ONE_THREAD.with(|c| c.set(true));
            let one = check(&wide);
            ONE_THREAD.with(|c| c.set(false));
            assert_eq!(format!("{:?}", threads.diagnostics), format!("{:?}", one.diagnostics));
            assert_eq!(format!("{:?}", threads.specs), format!("{:?}", one.specs));
            if name.starts_with("invalid") {
                let code = &name[8..15];
                assert!(
                    threads.diagnostics.iter().any(|d| d.code == code),
                    "{name}: {:?}",
                    threads.diagnostics
                );
            }
        }
    }
}
