//! Shared and deep lets through the facade (issue 11, classes 1 and 2): a let used twice
//! is computed once, and nothing recurses along a chain of lets, so a doubling chain of
//! 30 lets (a tree of 2^29 atoms), 80 lets of 250 `!` and a chain of 300 lets monitor,
//! score and lower with the values of the small spec they equal.

use hstl::load::load;
use hstl::monitor::{Monitor, Samples};
use hstl::reward::EpisodeMonitor;

/// A persistent spec over `x` and `y` with `lets`, whose region `B` is `top`.
fn spec(lets: &str, top: &str) -> String {
    format!(
        "spec S {{
            state {{ x: int in 0..=14, y: int in 0..=14 }}
            let A = x < 3 && y < 3;
            {lets}
            let B = {top};
            task always[0..] (eventually[0..40] A && eventually[0..40] B);
            option A;
            option B;
        }}"
    )
}

fn trace() -> (Vec<f64>, Vec<f64>) {
    let x = (0..300).map(|t| ((t * 7) % 15) as f64).collect();
    let y = (0..300).map(|t| ((t * 11) % 15) as f64).collect();
    (x, y)
}

/// Signals of the task and of `B`, the task's score state by state, and the task spec's
/// region: what a spec gives through the facade.
fn run(src: &str) -> (Vec<f64>, Vec<f64>, Vec<f64>, f64) {
    let loaded = load(src, None).unwrap_or_else(|e| panic!("{e}"));
    let (x, y) = trace();
    let samples = Samples::Columns(vec![&x, &y]);
    let task = Monitor::new(&loaded.spec, None).expect("the task lowers");
    let region = Monitor::new(&loaded.spec, Some("B")).expect("B lowers");
    let mut episode = EpisodeMonitor::new(&loaded.spec, src, None).expect("an episode monitor");
    let scores = (0..x.len())
        .map(|t| episode.push(&[x[t], y[t]]).expect("a state").task_robustness)
        .collect();
    let spec = hstl::lower::task_spec(&loaded.spec, src).expect("the spec lowers");
    let states = hstl::robustness::Trace::from_columns(vec![x.clone(), y.clone()]).expect("xy");
    let r = hstl::robustness::offline::robustness(&spec.regions[1].formula, &states);
    (task.signal(&samples).expect("signal"), region.signal(&samples).expect("signal"), scores, r)
}

#[test]
fn shared_and_deep_lets_give_the_small_specs_values() {
    let plain = run(&spec("", "x > 11 && y > 11"));
    let mut doubling = String::from("let L0 = x > 11 && y > 11;\n");
    for k in 1..30 {
        doubling.push_str(&format!("let L{k} = L{} && L{};\n", k - 1, k - 1));
    }
    assert_eq!(run(&spec(&doubling, "L29")), plain);
    let mut deep = String::from("let M0 = x > 11 && y > 11;\n");
    for k in 1..=80 {
        deep.push_str(&format!("let M{k} = {}M{};\n", "!".repeat(250), k - 1));
    }
    assert_eq!(run(&spec(&deep, "M80")), plain);
    // 300 lets in a chain, past the old limit of 256 inlined lets.
    let mut chain = String::from("let C0 = x > 11;\n");
    for k in 1..300 {
        chain.push_str(&format!("let C{k} = C{} && y > 11;\n", k - 1));
    }
    let src = spec(&chain, "C299");
    let checked = hstl::lang::check(&src);
    assert!(checked.diagnostics.is_empty(), "{:?}", checked.diagnostics);
    assert_eq!(run(&src), plain);
}
