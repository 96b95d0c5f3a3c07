//! The episode monitor (`hstl::reward`) against the offline evaluator on every prefix of
//! a trace: the reward at step `t` is the last value of the signal over `s_0 ..= s_t`, the
//! task's robustness is `rho(task, 0)` over it, and the window kept is the window rate's
//! `psi(t)`. Tasks: every task of the rtamt oracle files (past-time operators included)
//! and random formulas of every shape (unbounded, nested, until).

use hstl::load::load;
use hstl::reward::{EpisodeMonitor, RewardError, RewardForm, Shaping, StepScore};
use hstl::robustness::{Trace, offline};
use hstl::runtime::eval::RegionTable;
use hstl::runtime::{Env, GridWorld};
use serde_json::Value;

const ORACLE: &str = include_str!("../robustness/tests/data/rtamt-cases.jsonl");

/// Equal, with `0 == -0` and NaN equal to NaN.
fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

/// A small reproducible generator (splitmix64), and how far past its start an interval
/// may end (5 unless set).
struct Draws(u64, u64);

impl Draws {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    fn interval(&mut self) -> String {
        let a = self.below(4);
        match self.below(3) {
            0 => format!("[{a}..]"),
            1 => format!("[{a}..={}]", a + self.below(self.1)),
            _ => format!("[{a}..{}]", a + 1 + self.below(self.1)),
        }
    }

    fn formula(&mut self, depth: u32) -> String {
        let atom = |d: &mut Draws| {
            let var = if d.below(2) == 0 { "x" } else { "y" };
            let op = ["<", "<=", ">", ">="][d.below(4) as usize];
            format!("({var} {op} {})", d.below(10) as i64 - 3)
        };
        if depth == 0 {
            return atom(self);
        }
        match self.below(9) {
            0 => atom(self),
            1 => format!("!{}", self.formula(depth - 1)),
            2 => format!("({} && {})", self.formula(depth - 1), self.formula(depth - 1)),
            3 => format!("({} || {})", self.formula(depth - 1), self.formula(depth - 1)),
            4 => format!("({} -> {})", self.formula(depth - 1), self.formula(depth - 1)),
            5 => format!("always{} {}", self.interval(), self.formula(depth - 1)),
            6 => format!("eventually{} {}", self.interval(), self.formula(depth - 1)),
            _ => format!(
                "({} until{} {})",
                self.formula(depth - 1),
                self.interval(),
                self.formula(depth - 1)
            ),
        }
    }
}

impl Draws {
    /// A formula with future and past operators in any nesting (`next` and `prev` too).
    fn mixed_formula(&mut self, depth: u32) -> String {
        if depth == 0 || self.below(8) == 0 {
            return self.formula(0);
        }
        let f = |d: &mut Draws| d.mixed_formula(depth - 1);
        match self.below(12) {
            0 => format!("!{}", f(self)),
            1 => format!("({} && {})", f(self), f(self)),
            2 => format!("({} || {})", f(self), f(self)),
            3 => format!("always{} {}", self.interval(), f(self)),
            4 => format!("eventually{} {}", self.interval(), f(self)),
            5 => format!("({} until{} {})", f(self), self.interval(), f(self)),
            6 => format!("next {}", f(self)),
            7 => format!("once{} {}", self.interval(), f(self)),
            8 => format!("historically{} {}", self.interval(), f(self)),
            9 => format!("({} since{} {})", f(self), self.interval(), f(self)),
            10 => format!("prev {}", f(self)),
            _ => format!("({} -> {})", f(self), f(self)),
        }
    }
}

fn spec_text(task: &str) -> String {
    format!("spec T {{ state {{ x: float, y: float }} task {task}; }}")
}

/// Pushes the trace state by state and holds every step against the offline evaluator
/// on the prefix so far.
fn check_prefixes(task: &str, x: &[f64], y: &[f64]) {
    let src = spec_text(task);
    let loaded = load(&src, None).unwrap_or_else(|e| panic!("{task}: {e}"));
    let formula = hstl::lower::task(&loaded.spec).unwrap();
    let mut episode = EpisodeMonitor::new(&loaded.spec, &src, None).unwrap();
    for round in 0..2 {
        // The second round after a reset: nothing of the first may remain.
        episode.reset();
        let mut prefix = Trace::new(2);
        for t in 0..x.len() {
            prefix.push(&[x[t], y[t]]).unwrap();
            let score = episode.push(&[x[t], y[t]]).unwrap();
            let signal = offline::signal(&formula, &prefix);
            let want = offline::robustness(&formula, &prefix);
            assert!(
                same(score.task_robustness, want),
                "{task}, round {round}, step {t}: task robustness {} but offline {want}",
                score.task_robustness
            );
            assert!(same(score.reward, signal[t]), "{task}, step {t}: reward {}", score.reward);
            // (Whether the window is kept is held against the window rate below.)
            assert_eq!(score.window_kept.is_some(), episode.is_persistent(), "{task}");
        }
    }
}

#[test]
fn the_oracle_tasks_agree_with_the_offline_evaluator_on_every_prefix() {
    let mut cases = 0;
    for line in ORACLE.lines().filter(|l| !l.trim().is_empty()) {
        let c: Value = serde_json::from_str(line).unwrap();
        let column = |v: &Value| -> Vec<f64> {
            v.as_array().unwrap().iter().map(|n| n.as_f64().unwrap()).collect()
        };
        let task = c["task"].as_str().unwrap();
        check_prefixes(task, &column(&c["trace"]["x"]), &column(&c["trace"]["y"]));
        cases += 1;
    }
    assert!(cases >= 100);
}

/// The past-time tasks: the reward at `t` reads the states before `s_t` too.
#[test]
fn the_past_time_oracle_tasks_agree_with_the_offline_evaluator_on_every_prefix() {
    let past = include_str!("../robustness/tests/data/rtamt-past-cases.jsonl");
    let mut cases = 0;
    for line in past.lines().filter(|l| !l.trim().is_empty()) {
        let c: Value = serde_json::from_str(line).unwrap();
        let column = |v: &Value| -> Vec<f64> {
            v.as_array().unwrap().iter().map(|n| n.as_f64().unwrap()).collect()
        };
        let task = c["task"].as_str().unwrap();
        check_prefixes(task, &column(&c["trace"]["x"]), &column(&c["trace"]["y"]));
        cases += 1;
    }
    assert_eq!(cases, 1500);
}

#[test]
fn random_formulas_agree_with_the_offline_evaluator_on_every_prefix() {
    let mut draws = Draws(2016, 5);
    for _ in 0..400 {
        let task = draws.formula(3);
        let len = 1 + draws.below(25) as usize;
        let mut values = || (0..len).map(|_| draws.below(9) as f64 - 3.0).collect::<Vec<_>>();
        let (x, y) = (values(), values());
        check_prefixes(&task, &x, &y);
    }
}

/// Future operators over past ones (the reward read at the last step: online), past ones
/// over future ones (the prefix evaluated again), and both mixed: every step's reward is
/// the offline signal's, bit for bit.
#[test]
fn random_past_and_future_formulas_agree_with_the_offline_evaluator_on_every_prefix() {
    let mut draws = Draws(2026, 5);
    for _ in 0..400 {
        let task = draws.mixed_formula(4);
        let len = 1 + draws.below(25) as usize;
        let mut values = || (0..len).map(|_| draws.below(9) as f64 - 3.0).collect::<Vec<_>>();
        let (x, y) = (values(), values());
        check_prefixes(&task, &x, &y);
    }
}

/// Past windows over future ones reaching back `FEW_STATES` steps or more: the reward from
/// the online monitor's open steps rather than from the last states evaluated again.
#[test]
fn wide_past_windows_over_future_ones_agree_with_the_offline_evaluator_on_every_prefix() {
    let mut draws = Draws(2027, 200);
    let mut wide = 0;
    for _ in 0..60 {
        let inner = draws.mixed_formula(2);
        let outer = ["once", "historically"][draws.below(2) as usize];
        let task =
            format!("{outer}{} eventually[0..={}] {inner}", draws.interval(), draws.below(4));
        let len = 150 + draws.below(100) as usize;
        let mut values = || (0..len).map(|_| draws.below(9) as f64 - 3.0).collect::<Vec<_>>();
        let (x, y) = (values(), values());
        check_prefixes(&task, &x, &y);
        let reach = hstl::robustness::segment::start_reach(&parsed(&task));
        wide += usize::from(reach.is_none_or(|r| r >= hstl::reward::FEW_STATES));
    }
    assert!(wide >= 30, "only {wide} of 60 tasks read back `FEW_STATES` steps or more");
}

fn parsed(task: &str) -> hstl::robustness::Formula {
    let src = spec_text(task);
    hstl::lower::task(&load(&src, None).expect("the task checks").spec).expect("it lowers")
}

#[test]
fn persistent_shapes_agree_with_the_offline_evaluator_on_every_prefix() {
    // `always[c..]` over `&&`s of `eventually[J]` (and the duals) of state formulas: the
    // shapes kept up to date in O(1) a step, with empty and clipped windows, and `J`
    // without an end ("infinitely often").
    let mut draws = Draws(40, 5);
    for _ in 0..300 {
        let (outer, inner, join) = if draws.below(2) == 0 {
            ("always", "eventually", "&&")
        } else {
            ("eventually", "always", "||")
        };
        let parts: Vec<String> = (0..1 + draws.below(3))
            .map(|_| {
                let a = draws.below(3);
                let end = match draws.below(4) {
                    0 => format!("..={}", a + draws.below(6)),
                    1 => format!("..{}", a + 1 + draws.below(6)),
                    2 => "..".to_string(),
                    _ => format!("..={}", a + 20),
                };
                format!("{inner}[{a}{end}] {}", draws.formula(0))
            })
            .collect();
        let task = format!("{outer}[{}..] ({})", draws.below(3), parts.join(&format!(" {join} ")));
        let len = 1 + draws.below(40) as usize;
        let mut values = || (0..len).map(|_| draws.below(9) as f64 - 3.0).collect::<Vec<_>>();
        let (x, y) = (values(), values());
        check_prefixes(&task, &x, &y);
    }
}

#[test]
fn the_window_kept_is_the_window_rates_psi() {
    let src = "spec P { state { x: int in 0..=14, y: int in 0..=14 }
        let A = x < 4 && y < 4;
        let B = x > 10;
        task always[0..] (eventually[0..12] A && eventually[0..=5] B); }";
    let loaded = load(src, None).unwrap();
    let spec = hstl::lower::task_spec(&loaded.spec, src).unwrap();
    let world = GridWorld::builtin("paper").unwrap();
    let regions = RegionTable::new(&spec, &world).unwrap();
    let mut draws = Draws(7, 5);
    // A walk that crosses the grid often, so that both regions come and go.
    let (mut x, mut y) = (7i64, 7i64);
    let mut states = Vec::new();
    for _ in 0..3000 {
        let step =
            |v: i64, d: &mut Draws| (v + [-2, -1, 0, 1, 2][d.below(5) as usize]).clamp(0, 14);
        (x, y) = (step(x, &mut draws), step(y, &mut draws));
        states.push(world.index(&hstl::runtime::Cell { x: x as usize, y: y as usize }));
    }
    let psi = regions.psi(&states);
    assert!(psi.iter().any(|&k| k) && psi.iter().any(|&k| !k), "the walk keeps some windows");
    let mut episode = EpisodeMonitor::new(&loaded.spec, src, Some("A")).unwrap();
    assert!(episode.is_persistent());
    let task = hstl::lower::task(&loaded.spec).unwrap();
    let a = hstl::lower::let_formula(&loaded.spec, "A").unwrap();
    let mut prefix = Trace::new(2);
    for (t, &s) in states.iter().enumerate() {
        let cell = world.state(s).unwrap();
        let state = [cell.x as f64, cell.y as f64];
        prefix.push(&state).unwrap();
        let score = episode.push(&state).unwrap();
        assert_eq!(score.window_kept, Some(psi[t]), "step {t}");
        // A region's reward is its full signal, step for step.
        let one = Trace::from_columns(vec![vec![state[0]], vec![state[1]]]).unwrap();
        assert_eq!(score.reward.to_bits(), offline::robustness(&a, &one).to_bits());
        if t % 250 == 0 {
            assert!(same(score.task_robustness, offline::robustness(&task, &prefix)), "step {t}");
        }
    }
}

#[test]
fn bad_states_are_refused_and_change_nothing() {
    let src = spec_text("eventually[0..] (x > 2)");
    let loaded = load(&src, None).unwrap();
    let mut episode = EpisodeMonitor::new(&loaded.spec, &src, None).unwrap();
    episode.push(&[1.0, 0.0]).unwrap();
    let e = episode.push(&[f64::NAN, 0.0]).unwrap_err();
    assert_eq!(e.to_string(), "`x` is NaN at step 1");
    let e = episode.push(&[1.0]).unwrap_err();
    assert!(e.to_string().contains("1 value"), "{e}");
    assert_eq!(episode.steps(), 1);
    assert_eq!(episode.push(&[5.0, 0.0]).unwrap().task_robustness, 3.0);
    let e = EpisodeMonitor::new(&loaded.spec, &src, Some("Nope")).unwrap_err();
    assert_eq!(e.to_string(), "spec `T` has no `let` named `Nope` (it has no lets)");
}

/// The oracle's tasks with their traces.
fn oracle_cases() -> Vec<(String, Vec<f64>, Vec<f64>)> {
    let column = |v: &Value| -> Vec<f64> {
        v.as_array().unwrap().iter().map(|n| n.as_f64().unwrap()).collect()
    };
    ORACLE
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let c: Value = serde_json::from_str(line).unwrap();
            let task = c["task"].as_str().unwrap().to_string();
            (task, column(&c["trace"]["x"]), column(&c["trace"]["y"]))
        })
        .collect()
}

fn shaped(src: &str, formula: Option<&str>, shaping: Shaping) -> EpisodeMonitor {
    let loaded = load(src, None).unwrap();
    EpisodeMonitor::new(&loaded.spec, src, formula).unwrap().with_shaping(shaping, formula).unwrap()
}

fn form(form: RewardForm) -> Shaping {
    Shaping { form, ..Shaping::default() }
}

#[test]
fn increments_add_up_to_the_robustness_over_the_episode() {
    for (task, x, y) in oracle_cases() {
        let src = spec_text(&task);
        let mut episode = shaped(&src, None, form(RewardForm::Increment));
        for _round in 0..2 {
            episode.reset();
            let first = episode.push(&[x[0], y[0]]).unwrap();
            assert_eq!(first.reward, 0.0, "{task}: the reset's state earns nothing");
            let mut sum = 0.0;
            let mut last = first.task_robustness;
            for t in 1..x.len() {
                let score = episode.push(&[x[t], y[t]]).unwrap();
                sum += score.reward;
                last = score.task_robustness;
            }
            let want = if last.is_finite() { last } else { 0.0 };
            assert!((sum - want).abs() <= 1e-9 * want.abs().max(1.0), "{task}: {sum} vs {want}");
        }
    }
}

#[test]
fn the_sparse_reward_is_the_robustness_at_the_last_state_only() {
    for (task, x, y) in oracle_cases().into_iter().take(40) {
        let src = spec_text(&task);
        let mut episode = shaped(&src, None, form(RewardForm::Sparse));
        let n = x.len();
        for t in 0..n - 1 {
            assert_eq!(episode.push(&[x[t], y[t]]).unwrap().reward, 0.0, "{task}");
        }
        let end = episode.push_last(&[x[n - 1], y[n - 1]]).unwrap();
        assert!(same(end.reward, end.task_robustness), "{task}");
    }
}

#[test]
fn a_let_is_rewarded_by_its_own_prefix_robustness() {
    let src = "spec S { state { x: float } let Hot = x > 2; \
               task always[0..] eventually[0..=3] Hot; }";
    let mut episode = shaped(src, Some("Hot"), form(RewardForm::Increment));
    let rewards: Vec<f64> =
        [1.0, 5.0, 0.0, 7.0].iter().map(|&x| episode.push(&[x]).unwrap().reward).collect();
    // rho(Hot, 0) over every prefix is Hot at step 0: -1 throughout, after the first 0.
    assert_eq!(rewards, [0.0, -1.0, 0.0, 0.0]);
    let mut sparse = shaped(src, Some("Hot"), form(RewardForm::Sparse));
    sparse.push(&[4.0]).unwrap();
    assert_eq!(sparse.push_last(&[0.0]).unwrap().reward, 2.0);
}

#[test]
fn the_window_reward_counts_kept_windows_and_offset_and_scale_apply() {
    let src = "spec S { state { x: float } let Hot = x > 2; \
               task always[0..] eventually[0..=1] Hot; }";
    let shaping = Shaping { form: RewardForm::Window, offset: -0.5, scale: 2.0 };
    let mut episode = shaped(src, None, shaping);
    let rewards: Vec<f64> =
        [5.0, 0.0, 0.0, 0.0, 3.0].iter().map(|&x| episode.push(&[x]).unwrap().reward).collect();
    // Kept, kept (held one step ago), lost, lost, kept: 2 * (1 or 0) - 0.5.
    assert_eq!(rewards, [1.5, 1.5, -0.5, -0.5, 1.5]);
    let mut robust =
        shaped(src, None, Shaping { offset: 1.0, scale: 0.5, ..form(RewardForm::Robustness) });
    assert_eq!(robust.push(&[4.0]).unwrap().reward, 0.5 * 2.0 + 1.0);
}

#[test]
fn reward_forms_that_do_not_fit_are_refused_with_a_way_out() {
    let src = spec_text("eventually[0..] (x > 2)");
    let loaded = load(&src, None).unwrap();
    let episode = || EpisodeMonitor::new(&loaded.spec, &src, None).unwrap();
    let e = episode().with_shaping(form(RewardForm::Window), None).unwrap_err();
    assert_eq!(
        e.to_string(),
        "reward form `window` needs a persistent task, and this task is not one"
    );
    assert!(e.help().unwrap().contains("`increment`"));
    let e = RewardForm::parse("dense").unwrap_err();
    assert_eq!(e.to_string(), "unknown reward form `dense`");
    assert_eq!(e.help().unwrap(), "the forms are `robustness`, `increment`, `window`, `sparse`");
    for bad in [0.0, -1.0, f64::INFINITY, f64::NAN] {
        let e = episode().with_shaping(Shaping { scale: bad, ..Shaping::default() }, None);
        assert!(matches!(e, Err(RewardError::Scale(_))), "{bad}");
    }
    let e = episode().with_shaping(Shaping { offset: f64::NAN, ..Shaping::default() }, None);
    assert!(matches!(e, Err(RewardError::Offset(_))));
    for f in RewardForm::ALL {
        assert_eq!(RewardForm::parse(f.name()), Ok(f));
    }
}

#[test]
fn an_episode_monitor_restored_from_its_states_continues_exactly() {
    for (task, x, y) in oracle_cases().into_iter().step_by(7) {
        let src = spec_text(&task);
        for f in [RewardForm::Robustness, RewardForm::Increment, RewardForm::Sparse] {
            let mut whole = shaped(&src, None, form(f));
            let want: Vec<StepScore> =
                (0..x.len()).map(|t| whole.push(&[x[t], y[t]]).unwrap()).collect();
            for cut in [0, 1, x.len() / 2, x.len()] {
                let mut first = shaped(&src, None, form(f));
                for t in 0..cut {
                    first.push(&[x[t], y[t]]).unwrap();
                }
                let mut back = shaped(&src, None, form(f));
                back.restore(first.episode_states()).unwrap();
                assert_eq!(back.steps(), cut);
                for t in cut..x.len() {
                    let got = back.push(&[x[t], y[t]]).unwrap();
                    let w = want[t];
                    assert!(
                        same(got.reward, w.reward) && same(got.task_robustness, w.task_robustness),
                        "{task}, {f:?}, cut {cut}, step {t}"
                    );
                }
            }
        }
    }
}

/// A state where an expression of the task computes NaN is refused, naming the step and
/// the expression, whatever part of the task it is in (a region of a persistent task, a
/// safety conjunct, a `let` rewarded on its own), and changes nothing.
#[test]
fn a_state_where_an_expression_is_nan_is_refused_in_every_part() {
    let src = "spec T { state { x: float, y: float } let R = sqrt(x) > 1; let Safe = y / x < 5; \
               task always[0..] eventually[0..=3] R && always[0..] Safe; }";
    let loaded = load(src, None).unwrap();
    for formula in [None, Some("R"), Some("Safe")] {
        let mut episode = EpisodeMonitor::new(&loaded.spec, src, formula).unwrap();
        episode.push(&[4.0, 1.0]).unwrap();
        for (state, culprit) in [([-1.0, 1.0], "sqrt"), ([0.0, 0.0], "/")] {
            let e = episode.push(&state).unwrap_err().to_string();
            assert!(e.contains("step 1") && e.contains(culprit), "{formula:?} {state:?}: {e}");
            assert_eq!(episode.steps(), 1);
        }
        let mut fresh = EpisodeMonitor::new(&loaded.spec, src, formula).unwrap();
        fresh.push(&[4.0, 1.0]).unwrap();
        assert_eq!(episode.push(&[0.25, 0.0]).unwrap(), fresh.push(&[0.25, 0.0]).unwrap());
    }
}
