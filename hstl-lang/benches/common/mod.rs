//! The generated spec both benches read.

use std::fmt::Write as _;

/// A spec of about `lines` lines. Each let compares the variables and every third one
/// also refers to one of the first 97 lets (shared helpers), so that name resolution and
/// the dependency order have work without building one 3,000-let chain.
pub fn big_spec(lines: usize) -> String {
    let mut s = String::from("/// Generated.\nspec Big {\n    state {\n");
    for v in 0..4 {
        let _ = writeln!(s, "        /// Variable {v}.\n        v{v}: int in 0..=9,");
    }
    s.push_str("    }\n");
    let lets = lines;
    for i in 0..lets {
        let (a, b) = (i % 4, (i + 1) % 4);
        if i >= 3 && i % 3 == 0 {
            let _ = writeln!(
                s,
                "    let L{i} = L{} || (v{a} + {} > v{b} && abs(v{a} - 3) < 2.5);",
                (i / 3) % 97 * 3 + 1,
                i % 7
            );
        } else {
            let _ = writeln!(
                s,
                "    let L{i} = {} < v{a} < {} && v{b} >= {}; // region {i}",
                i % 5,
                5 + i % 5,
                i % 3
            );
        }
    }
    let task: Vec<String> =
        (0..4).map(|k| format!("eventually[0..40] L{}", lets - 1 - k)).collect();
    let _ = writeln!(s, "    task always[0..] ({});", task.join(" && "));
    for k in 0..4 {
        let _ = writeln!(s, "    option L{};", lets - 1 - k);
    }
    s.push_str("    learn { episodes: 100, flat: { gamma: 0.95 } }\n}\n");
    s
}
