//! The approximate learner through the facade: a spec over a `float` state trains on a
//! plane world and on `mountain-car`, the same seed gives the same weights bit for bit, its
//! `policy.json` loads back to the same bits, and an edited document is refused.

use hstl::continuous::{self as c, Evaluation};
use hstl::world::AnyWorld;
use serde_json::Value;

/// Reach the top-right corner of `paper-plane` within 60 steps.
const REACH: &str = "spec Reach {
    world \"paper-plane\";
    state { x: float in 0..=14, y: float in 0..=14 }
    let A = x > 12 && y > 12;
    task eventually[0..60] A;
    option A;
    learn { preset: auto, episodes: 1500, choices: 3 }
}
";

/// Both corners of `paper-plane` within every 40 steps.
const PATROL: &str = "spec Patrol {
    world \"paper-plane\";
    state { x: float in 0..=14, y: float in 0..=14 }
    let A = x < 3 && y > 11;
    let B = x > 11 && y < 3;
    task always[0..] (eventually[0..40] A && eventually[0..40] B);
    option A;
    option B;
    learn { preset: auto, episodes: 30, choices: 20 }
}
";

/// Both hill tops of `mountain-car` within every `window` steps, trained `episodes`.
fn car(window: u32, episodes: u32) -> String {
    format!(
        "spec Car {{
        world \"mountain-car\";
        state {{ x: float in -1.2..=0.6, v: float in -0.07..=0.07 }}
        let Left = x < -1.0;
        let Right = x > 0.4;
        task always[0..] (eventually[0..{window}] Left && eventually[0..{window}] Right);
        option Left;
        option Right;
        learn {{ preset: auto, episodes: {episodes}, choices: 4 }}
    }}"
    )
}

fn lowered(src: &str, world: &AnyWorld) -> hstl::runtime::TaskSpec {
    let loaded = hstl::load::load(src, None).expect("the spec checks");
    let mut spec = hstl::train::trainable(&loaded.spec, src, "spec.hstl").expect("trainable");
    c::fit_tiles(&mut spec, &loaded.spec, world);
    spec
}

fn plane() -> AnyWorld {
    AnyWorld::builtin("paper-plane").expect("built in")
}

#[test]
fn the_same_seed_gives_the_same_weights_and_another_seed_others() {
    let world = plane();
    let spec = lowered(PATROL, &world);
    let bits = |seed| {
        let t = c::train(&spec, &world, seed, |_, _| {}).expect("trains");
        let w = &t.agent.weights;
        let mut all: Vec<u64> = w.flat.iter().flatten().map(|v| v.to_bits()).collect();
        all.extend(w.options.iter().map(|v| v.to_bits()));
        (all, t.curve.iter().map(|v| v.to_bits()).collect::<Vec<_>>())
    };
    let a = bits(7);
    assert_eq!(a, bits(7));
    assert_ne!(a, bits(8));
    assert!(a.0.iter().any(|&b| b != 0), "training changed no weight");
}

#[test]
fn a_reach_task_on_the_plane_is_learned() {
    let world = plane();
    let spec = lowered(REACH, &world);
    // The tiles follow the world's step: 14 per variable on [0, 14] with step 1.
    assert_eq!(spec.learn.tiles.as_ref().map(|t| t.bins.clone()), Some(vec![14, 14]));
    let t = c::train(&spec, &world, 1, |_, _| {}).expect("trains");
    match c::after_training(&spec, &world, &t.agent, 1).expect("evaluates") {
        Evaluation::Satisfaction { rate } => assert!(rate > 0.9, "P = {rate}"),
        other => panic!("a reach task is measured by satisfaction: {other:?}"),
    }
}

#[test]
fn policy_json_loads_back_to_the_same_bits_and_edits_are_refused() {
    let world = plane();
    let spec = lowered(PATROL, &world);
    let t = c::train(&spec, &world, 2, |_, _| {}).expect("trains");
    let text = c::policy_json(&spec, &world, &t.agent, PATROL, 2).expect("writes");
    let doc: Value = serde_json::from_str(&text).expect("JSON");
    assert!(c::is_learned_function(&doc));
    assert!(c::is_learned_function_text(&text));
    // A tabular policy, another document, and text that is not JSON are not.
    assert!(!c::is_learned_function_text(r#"{"spec": "S", "learner": 3, "flat_policies": {}}"#));
    assert!(!c::is_learned_function_text(r#"{"learner": "table"}"#));
    assert!(!c::is_learned_function_text("[1, 2]"));
    // A document cut off after `"learner": "tiles"` is one, so that its error says where
    // it breaks off rather than what a table lacks.
    assert!(c::is_learned_function_text("{\"learner\": \"tiles\""));
    assert!(!c::is_learned_function_text("{\"learner\": \"til"));
    let replay = c::replay(&doc).expect("loads");
    assert_eq!(replay.seed, Some(2));
    // Read from the text in one pass (the weights straight into pairs), the same agent.
    let streamed = c::replay_text(&text).expect("loads from text");
    assert_eq!(streamed.agent.weights, replay.agent.weights);
    let bits = |w: &hstl::runtime::approx::Weights| -> Vec<u64> {
        w.flat.iter().flatten().chain(&w.options).map(|v| v.to_bits()).collect()
    };
    assert!(bits(&replay.agent.weights) == bits(&t.agent.weights), "the weights differ");
    assert_eq!(
        (replay.agent.weights.steps, replay.agent.weights.choices),
        (t.agent.weights.steps, t.agent.weights.choices)
    );
    // The same greedy runs from the same seed.
    let runs = hstl::evaluate::Runs { starts: 3, steps: 300, burn_in: 10, seed: 5 };
    let again = c::Replay { agent: t.agent.clone(), ..replay.clone() };
    assert_eq!(c::evaluate(&replay, runs).unwrap(), c::evaluate(&again, runs).unwrap());
    // Edits: a tiling that is not the spec's, an index out of range, a value that is not
    // finite, a primitive missing, a grid as the world.
    let edit = |f: &dyn Fn(&mut Value)| {
        let mut d = doc.clone();
        f(&mut d);
        let from_doc = c::replay(&d).map(|_| ()).expect_err("an edited document is refused");
        let text = serde_json::to_string(&d).expect("writes");
        let from_text = c::replay_text(&text).map(|_| ()).expect_err("and its text too");
        assert_eq!(from_doc.message, from_text.message);
        from_doc.message
    };
    let msg = edit(&|d| d["tiles"]["bins"] = serde_json::json!([13, 14]));
    assert!(msg.contains("tiles"), "{msg}");
    let one = format!("{:016x}", 1.0f64.to_bits());
    let msg = edit(&|d| d["weights"]["options"] = serde_json::json!([[usize::MAX, one]]));
    assert!(msg.contains("out of range"), "{msg}");
    let msg = edit(&|d| d["weights"]["flat"]["A"] = serde_json::json!([[0, 1.5]]));
    assert!(msg.contains("hex digits"), "{msg}");
    let inf = format!("{:016x}", f64::INFINITY.to_bits());
    let msg = edit(&|d| d["weights"]["flat"]["A"] = serde_json::json!([[0, inf]]));
    assert!(msg.contains("finite"), "{msg}");
    let msg = edit(&|d| {
        d["weights"]["flat"].as_object_mut().unwrap().remove("B");
    });
    assert!(msg.contains("primitive"), "{msg}");
    let msg = edit(&|d| {
        d["env"] = serde_json::json!({"name": "tiny", "params": {"slip": 0.3, "map": ["..", ".."]}})
    });
    assert!(msg.contains("grid"), "{msg}");
    // Weights of the wrong type anywhere, and text that is not a whole document.
    for weights in [serde_json::json!(3), serde_json::json!({"flat": [1], "options": "x"})] {
        let msg = edit(&|d| d["weights"] = weights.clone());
        assert!(msg.contains("weights"), "{msg}");
    }
    let cut = &text[..text.len() / 2];
    let msg = c::replay_text(cut).map(|_| ()).expect_err("a cut document").message;
    assert!(msg.starts_with("not a valid policy.json"), "{msg}");
    assert!(!msg.ends_with('.'), "{msg}");
}

#[test]
fn greedy_runs_as_data_have_the_contract_s_columns() {
    let world = plane();
    let spec = lowered(PATROL, &world);
    let t = c::train(&spec, &world, 2, |_, _| {}).expect("trains");
    let replay =
        c::Replay { spec, world, agent: t.agent, source: PATROL.to_string(), seed: Some(2) };
    let runs = c::greedy_runs(&replay, 2, 25, 9);
    assert_eq!(runs.len(), 2);
    let csv = c::run_csv(&replay, &runs[0]);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "t,x,y,action,option");
    // 25 actions, 26 rows; the last holds the final state with empty action and option.
    assert_eq!(lines.len(), 1 + 26);
    assert!(lines[26].starts_with("25,") && lines[26].ends_with(",,"), "{}", lines[26]);
    for line in &lines[1..26] {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), 5, "{line}");
        let (x, y): (f64, f64) = (cells[1].parse().unwrap(), cells[2].parse().unwrap());
        assert!((0.0..=14.0).contains(&x) && (0.0..=14.0).contains(&y), "{line}");
        assert!(["E", "N", "W", "S"].contains(&cells[3]), "{line}");
        assert!(["A", "B"].contains(&cells[4]), "{line}");
    }
}

#[test]
fn mountain_car_trains_with_its_own_tiling() {
    let world = AnyWorld::builtin("mountain-car").expect("built in");
    let src = &car(200, 3);
    let spec = lowered(src, &world);
    assert_eq!(spec.learn.tiles.as_ref().map(|t| t.bins.clone()), Some(vec![12, 12]));
    let t = c::train(&spec, &world, 0, |_, _| {}).expect("trains");
    assert_eq!(t.curve.len(), 3);
    let text = c::policy_json(&spec, &world, &t.agent, src, 0).expect("writes");
    let replay = c::replay(&serde_json::from_str(&text).unwrap()).expect("loads");
    assert_eq!(replay.world, world);
}

/// The trimmed contents of every `<text>` of an SVG.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let body = &t[t.find('>')? + 1..];
            Some(body[..body.find("</text>")?].trim().to_owned())
        })
        .collect()
}

/// The pictures of a learned function are named as a grid's (`flat_OPTION.svg`,
/// `options.svg`, `run_K.svg`), draw the spec's regions by kind, and count the blocked
/// moves of the greedy runs they draw: replaying them with the pictures' generator finds as
/// many moves after which the robot stayed put as each picture says.
#[test]
fn plane_pictures_are_named_as_the_grid_s_and_count_blocked_moves() {
    let world = plane();
    let src = "spec Careful {
        world \"paper-plane\";
        state { x: float in 0..=14, y: float in 0..=14 }
        let A = x > 12 && y > 12;
        let Pond = (x - 7) * (x - 7) + (y - 7) * (y - 7) < 4;
        task eventually[0..60] A && always[0..60] !Pond;
        option A;
        learn { preset: auto, episodes: 20, choices: 3 }
    }";
    let loaded = hstl::load::load(src, None).expect("the spec checks");
    let spec = lowered(src, &world);
    let t = c::train(&spec, &world, 1, |_, _| {}).expect("trains");
    let files = hstl::artifacts::plane_pictures(&spec, &world, &loaded.spec, &t.agent, "c.hstl", 4)
        .expect("draws");
    let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["flat_A.svg", "options.svg", "run_1.svg", "run_2.svg"]);
    let text = |name: &str| {
        let f = files.iter().find(|f| f.name == name).expect("written");
        String::from_utf8(f.contents.clone()).expect("utf-8")
    };
    let flat = text("flat_A.svg");
    let words = texts(&flat);
    for wanted in ["c.hstl: flat policy of option A", "seed 4", "Pond", "region to avoid", "A"] {
        assert!(words.iter().any(|t| t == wanted), "flat_A.svg lacks {wanted}: {words:?}");
    }
    let options = text("options.svg");
    assert!(options.contains("c.hstl: options policy") && !options.contains("one step after"));
    let AnyWorld::Plane(w) = &world else { panic!("a plane") };
    let mut rng = hstl::runtime::seeded_rng(4 ^ hstl::train::PICTURE_SEED);
    // A run as long as the task: `eventually[0..60]` spans steps 0 to 59.
    let steps = spec.task.horizon().expect("bounded") + 1;
    assert_eq!(steps, 60);
    for k in 1..=2 {
        let start = hstl::runtime::World::reset(w, &mut rng);
        let run = t.agent.run(w, start, steps, &mut rng);
        let points: Vec<&[f64]> = run.values.chunks(2).collect();
        let blocked = points.windows(2).filter(|p| p[0] == p[1]).count();
        let svg = text(&format!("run_{k}.svg"));
        let summary = format!("blocked: {blocked}");
        assert!(
            texts(&svg).iter().any(
                |t| t.starts_with("60 moves, ") && t.ends_with(&format!(", {blocked} blocked"))
            ),
            "run {k}: {summary}, the picture: {:?}",
            texts(&svg).iter().find(|t| t.contains(" moves, "))
        );
    }
}

/// `mountain-car`'s pictures are drawn in its `(x, v)` phase plane, named by the spec's
/// variables.
#[test]
fn mountain_car_pictures_are_drawn_in_the_phase_plane() {
    let world = AnyWorld::builtin("mountain-car").expect("built in");
    let src = &car(100, 2);
    let loaded = hstl::load::load(src, None).expect("the spec checks");
    let spec = lowered(src, &world);
    let t = c::train(&spec, &world, 0, |_, _| {}).expect("trains");
    let files = hstl::artifacts::plane_pictures(&spec, &world, &loaded.spec, &t.agent, "car", 0)
        .expect("draws");
    let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["flat_Left.svg", "flat_Right.svg", "options.svg", "run_1.svg", "run_2.svg"]);
    let flat = String::from_utf8(files[0].contents.clone()).expect("utf-8");
    let words = texts(&flat);
    for wanted in ["v", "x", "0.00", "-1.0", "Left", "Right"] {
        assert!(words.iter().any(|t| t == wanted), "flat_Left.svg lacks {wanted}: {words:?}");
    }
    assert!(!flat.contains("start area") && !flat.contains("obstacle"));
    let run = String::from_utf8(files[3].contents.clone()).expect("utf-8");
    assert!(
        texts(&run).iter().any(|t| t == "200 moves, 0 slips, 0 blocked"),
        "twice the window, no slips"
    );
}

#[test]
fn the_planned_reference_reaches_and_patrols_and_refuses_a_grid() {
    use hstl::evaluate::Runs;
    use hstl::reference::Reference;
    let world = plane();
    let reach = Reference::new(&lowered(REACH, &world), &world).expect("plans");
    let runs = Runs { starts: 50, steps: 61, burn_in: 0, seed: 3 };
    match reach.evaluate(runs) {
        Evaluation::Satisfaction { rate } => assert!(rate > 0.9, "{rate}"),
        other => panic!("{other:?}"),
    }
    let patrol = Reference::new(&lowered(PATROL, &world), &world).expect("plans");
    let runs = Runs { starts: 5, steps: 600, burn_in: 100, seed: 3 };
    match patrol.evaluate(runs) {
        // Opposite corners about 22 moves apart within 40-step windows: with slip 0.3 a
        // move gains 0.6 of a step on average, so only some windows can be kept.
        Evaluation::Window(w) => assert!(w.rate > 0.25, "{}", w.rate),
        other => panic!("{other:?}"),
    }
    let grid = AnyWorld::builtin("paper").expect("built in");
    let e = Reference::new(&lowered(PATROL, &world), &grid).expect_err("a grid has W*");
    assert!(e.message.contains("grid"), "{}", e.message);
}

#[test]
fn a_crowded_plane_plans_on_a_coarser_lattice_within_its_budget() {
    let mut obstacles = String::new();
    for i in 0..1024 {
        let (x, y) = (5.0 + (i % 32) as f64 * 3.0, 5.0 + (i / 32) as f64 * 3.0);
        obstacles.push_str(&format!("{{ circle = [{x}, {y}, 0.5] }},\n"));
    }
    let toml = format!(
        "kind = \"plane\"\nx = [0.0, 100.0]\ny = [0.0, 100.0]\nstep = 0.5\nheadings = 8\n\
         obstacles = [\n{obstacles}]\n"
    );
    let world = AnyWorld::from_toml(&toml, "crowded").expect("a valid world");
    let src = PATROL
        .replace("world \"paper-plane\";", "")
        .replace("0..=14", "0..=100")
        .replace("x < 3 && y > 11", "x < 3 && y > 97")
        .replace("x > 11 && y < 3", "x > 97 && y < 3");
    let spec = lowered(&src, &world);
    // Planning is bounded by `MAX_PLAN_WORK` segment tests: it returns, and its legs move.
    let reference = hstl::reference::Reference::new(&spec, &world).expect("plans");
    let values = reference.run(50, &mut hstl::runtime::seeded_rng(1));
    assert_eq!(values.len(), 51 * 2);
    assert!(values.chunks(2).any(|p| p != &values[..2]), "the robot never moved");
}

/// Reach A, then B, then C, each within 16 steps, never touching O over 150 steps: the
/// goal is met in about 40, and the rest of the run must keep out of O. Exploration decays
/// within the short training, so that its runs meet the goal too.
const TIMED: &str = "spec Timed {
    state { x: float in 0..=10, y: float in 0..=10 }
    let A = x > 9 && y < 1;
    let B = x > 9 && y > 9;
    let C = x < 1 && y > 9;
    let O = sqrt((x - 5) * (x - 5) + (y - 5) * (y - 5)) < 2;
    task eventually[0..16] (A && eventually[0..16] (B && eventually[0..16] C)) && always[0..150] !O;
    option A;
    option B;
    option C;
    options { [A, B, C], C }
    learn { preset: auto, episodes: 1000, flat: { gamma: 0.9, decay: 0.00001 } }
}
";

#[test]
fn once_the_goal_is_met_the_options_level_holds_instead_of_starting_again() {
    let toml = "kind = \"plane\"\nx = [0.0, 10.0]\ny = [0.0, 10.0]\nstep = 1.0\nheadings = 8\n\
                slip = 0.05\nnoise = 0.05\nstart = [0.0, 0.0, 1.0, 1.0]\n";
    let world = AnyWorld::from_toml(toml, "field").expect("a valid world");
    let spec = lowered(TIMED, &world);
    let t = c::train(&spec, &world, 1, |_, _| {}).expect("trains");
    let m = &t.agent.model;
    assert_eq!(m.progress.as_ref().map(|p| p.goals()), Some(1), "the sequence is the goal");
    let replay = c::Replay {
        spec: spec.clone(),
        world: world.clone(),
        agent: t.agent.clone(),
        source: String::new(),
        seed: Some(1),
    };
    let (mut after, mut holding, mut satisfied) = (0, 0, 0);
    let runs = c::greedy_runs(&replay, 50, 150, 5);
    for run in &runs {
        let at = |s: usize| &run.values[s * 2..s * 2 + 2];
        let inside = |s: usize, f: fn(f64, f64) -> bool| f(at(s)[0], at(s)[1]);
        let a = (0..=150).find(|&s| inside(s, |x, y| x > 9.0 && y < 1.0));
        let b = a.and_then(|a| (a..=150).find(|&s| inside(s, |x, y| x > 9.0 && y > 9.0)));
        let met = b.and_then(|b| (b..=150).find(|&s| inside(s, |x, y| x < 1.0 && y > 9.0)));
        if let Some(met) = met {
            after += run.options.len() - met;
            holding += run.options[met..].iter().filter(|&&o| o == 1).count();
        }
        if hstl::runtime::approx::task_robustness(&spec, &run.values, 2) > 0.0 {
            satisfied += 1;
        }
    }
    // Starting [A, B, C] again from C crosses the field past O; C alone stays put.
    assert!(after > 0, "no run met the goal");
    assert!(holding as f64 >= 0.9 * after as f64, "{holding} of {after} steps held");
    assert!(satisfied >= 45, "{satisfied} of 50 runs satisfied the task");
}

/// A greedy run driven one step at a time from outside (`ApproxAgent::stepper`, what
/// `hstl.Policy.act` runs) takes the actions and options the agent's own run takes.
#[test]
fn a_run_stepped_from_outside_takes_the_agent_s_own_actions() {
    use hstl::runtime::World;
    let toml = "kind = \"plane\"\nx = [0.0, 10.0]\ny = [0.0, 10.0]\nstep = 1.0\nheadings = 8\n\
                slip = 0.05\nnoise = 0.05\nobstacles = [{ circle = [5.0, 5.0, 1.5] }]\n";
    let field = AnyWorld::from_toml(toml, "field").expect("a valid world");
    for (src, world) in [(PATROL, plane()), (TIMED, field)] {
        let spec = lowered(src, &world);
        let t = c::train(&spec, &world, 3, |_, _| {}).expect("trains");
        let AnyWorld::Plane(w) = &world else { unreachable!() };
        let mut rng = hstl::runtime::seeded_rng(8);
        for _ in 0..5 {
            let start = w.reset(&mut rng);
            let mut replay_rng = rng.clone();
            let run = t.agent.run(w, start, 200, &mut rng);
            let mut stepper = t.agent.stepper();
            let (mut state, mut x, mut blocked) = (start, Vec::new(), Vec::new());
            for k in 0..200 {
                w.valuation(&state, &mut x);
                assert_eq!(x[..], run.values[k * 2..k * 2 + 2]);
                blocked.clear();
                blocked.extend((0..w.actions().len()).map(|a| w.blocked(&state, a)));
                let (a, o) = stepper.act(&t.agent, &x, &blocked);
                assert_eq!((a, o), (run.actions[k], run.options[k]), "step {k}");
                state = w.step(&state, a, &mut replay_rng);
            }
        }
    }
}

/// `mountain-car`'s dynamics under a gymnasium environment's description, as the Python
/// package's `BoxEnv` presents one: what a policy trained through `hstl.train(env=...)`
/// records.
struct Described(hstl::runtime::MountainCar, hstl::gym::Described);

impl hstl::runtime::World for Described {
    type State = hstl::runtime::CarState;
    fn name(&self) -> &str {
        &self.1.name
    }
    fn params(&self) -> Value {
        self.1.params()
    }
    fn state_vars(&self) -> Vec<String> {
        self.1.vars.clone()
    }
    fn actions(&self) -> Vec<String> {
        hstl::runtime::World::actions(&self.1)
    }
    fn valuation(&self, s: &Self::State, out: &mut Vec<f64>) {
        self.0.valuation(s, out)
    }
    fn reset(&self, rng: &mut hstl::runtime::Rng) -> Self::State {
        self.0.reset(rng)
    }
    fn step(&self, s: &Self::State, a: usize, rng: &mut hstl::runtime::Rng) -> Self::State {
        self.0.step(s, a, rng)
    }
}

#[test]
fn a_policy_trained_in_a_described_environment_replays_against_its_spaces() {
    let src = car(200, 4);
    let world = AnyWorld::builtin("mountain-car").expect("built in");
    // The spec's own tiling: a described environment fits none (see `fit_tiles`).
    let loaded = hstl::load::load(&src, None).expect("the spec checks");
    let spec = hstl::train::trainable(&loaded.spec, &src, "car.hstl").expect("trainable");
    let vars = vec!["x".to_string(), "v".to_string()];
    let described = hstl::gym::Described::new(
        "MountainCarEnv",
        vars.clone(),
        vec![-1.2, -0.07],
        vec![0.6, 0.07],
        3,
        0,
    )
    .expect("bounded");
    let env = Described(hstl::runtime::MountainCar, described.clone());
    let t = c::train_world_until(&spec, &env, 5, |_, _| std::ops::ControlFlow::Continue(()))
        .expect("trains");
    let text = c::policy_json_in(&spec, &env, &t.agent, &src, 5).expect("writes");
    let doc: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(doc["env"]["params"]["gymnasium"], Value::Bool(true));
    let Ok(c::AnyReplay::Gym(replay)) = c::replay_text_any(&text) else {
        panic!("a gymnasium document replays as one");
    };
    assert_eq!(replay.env, described);
    assert_eq!(replay.agent.weights, t.agent.weights, "the same bits");
    // The world's own document (its tiling fitted to the world) replays as a world.
    let fitted = lowered(&src, &world);
    let native_agent = c::train(&fitted, &world, 5, |_, _| {}).expect("trains").agent;
    let native = c::policy_json(&fitted, &world, &native_agent, &src, 5).expect("writes");
    assert!(matches!(c::replay_text_any(&native), Ok(c::AnyReplay::World(_))), "a world's");
    // Spaces that contradict the document (an action count its actions do not have, a
    // bound that is no finite number) are refused, in words.
    for (from, to) in [("\"actions\": 3", "\"actions\": 4"), ("0.6", "1e999")] {
        let edited = text.replacen(from, to, 1);
        assert_ne!(edited, text, "{from} is in the document");
        match c::replay_text_any(&edited) {
            Ok(_) => panic!("{from} -> {to} was accepted"),
            Err(e) => assert!(!e.message.ends_with('.') && e.help.is_some(), "{}", e.message),
        }
    }
    // A bound nothing else in the document determines: the checksum refuses it edited;
    // in a document without one (written before checksums) it is read as written, and the
    // environment a replay is then given must have it (the Python package compares them).
    let bound = text.replacen("-0.07", "-0.08", 1);
    match c::replay_text_any(&bound) {
        Err(e) => assert!(e.message.contains("changed after it was written"), "{}", e.message),
        Ok(_) => panic!("an edited bound was read"),
    }
    let mut unsummed: Value = serde_json::from_str(&bound).expect("JSON");
    unsummed.as_object_mut().expect("an object").remove("checksum");
    match c::replay_text_any(&unsummed.to_string()) {
        Ok(c::AnyReplay::Gym(r)) => assert_eq!(r.env.low, vec![-1.2, -0.08]),
        _ => panic!("an edited bound reads as written"),
    }
    // Unbounded or empty spaces, and too many actions, give no environment.
    let cases: [(Vec<f64>, Vec<f64>, usize, &str); 4] = [
        (
            vec![f64::NEG_INFINITY, 0.0],
            vec![1.0, 1.0],
            2,
            "unbounded: component 0 lies in [-inf, 1]",
        ),
        (vec![0.0, 2.0], vec![1.0, 1.0], 2, "component 1 has low above high"),
        (vec![], vec![], 2, "has 0 components"),
        (vec![0.0, 0.0], vec![1.0, 1.0], 0, "has 0 actions"),
    ];
    for (low, high, actions, want) in cases {
        let e = hstl::gym::Described::new("E", vars.clone(), low, high, actions, 0).unwrap_err();
        assert!(e.message.contains(want), "{} does not hold {want}", e.message);
    }
}
