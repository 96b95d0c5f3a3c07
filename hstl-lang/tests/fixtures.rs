//! Data-driven tests over `tests/fixtures`: every invalid fixture's rendered diagnostics
//! are snapshotted and must contain the code its file name starts with; every valid
//! fixture checks without errors and its checked spec is summarised in a snapshot.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

use hstl_lang::{
    Bound, CFormula, CFormulaKind, Checked, CheckedSpec, Domain, SpecWorld, Terminate, WorldFacts,
    WorldProblem, codes, render_plain,
};

/// Checks a fixture: against the grid world its leading `// world:` comment draws (one
/// `// ` line per row, top first, `.` free, `#` wall, `S` start), or as a shell that reads
/// no file would: a spec naming a `.toml` world finds it missing (`HSTL034`), one naming
/// anything else is checked alone.
fn check(src: &str) -> Checked {
    match world_of(src) {
        Some(world) => hstl_lang::check_in_world(src, &world),
        None => {
            let missing = WorldProblem {
                message: "cannot read `maps/yrad.toml`: no such file or directory".into(),
                help: "check the path of the world file (relative to the spec file)".into(),
            };
            let parsed = hstl_lang::parse(src);
            hstl_lang::check_parsed_with_worlds(src, parsed, &|spec| match hstl_lang::world_item(
                spec,
            ) {
                Some(w) if w.name.ends_with(".toml") => SpecWorld::Unavailable(&missing),
                _ => SpecWorld::Alone,
            })
        }
    }
}

/// An open `width` x `height` grid, every cell a start.
fn open_world(width: usize, height: usize) -> WorldFacts {
    let cells = width * height;
    WorldFacts {
        label: format!("world `open{width}x{height}`"),
        width,
        height,
        free: vec![true; cells],
        reachable: vec![true; cells],
    }
}

/// The codes that only a world gives.
const WORLD_CODES: [&str; 5] = ["HSTL030", "HSTL031", "HSTL032", "HSTL034", "HSTL131"];

/// No check hides another: a world that does not fit (or fits with no walls) changes no
/// diagnostic of the spec's own, only adds its own codes.
#[test]
fn a_world_adds_to_the_diagnostics_and_hides_none() {
    let own = |c: &Checked| -> Vec<(String, std::ops::Range<usize>, String)> {
        c.diagnostics
            .iter()
            .filter(|d| !WORLD_CODES.contains(&d.code) && d.code != "HSTL024")
            .map(|d| (d.code.to_string(), d.range.clone(), d.message.clone()))
            .collect()
    };
    let mut mismatched = 0;
    for (name, src) in fixtures("invalid").into_iter().chain(fixtures("valid")) {
        if world_of(&src).is_some() {
            continue;
        }
        let alone = hstl_lang::check(&src);
        for world in [open_world(15, 15), open_world(13, 13), open_world(3, 1)] {
            let with = hstl_lang::check_in_world(&src, &world);
            assert_eq!(own(&alone), own(&with), "{name} against {}", world.label);
            mismatched += usize::from(with.diagnostics.iter().any(|d| d.code == "HSTL030"));
        }
    }
    // The property is exercised on specs the world does not fit, not only on ones it does.
    assert!(mismatched > 20, "only {mismatched} mismatches");
}

fn world_of(src: &str) -> Option<WorldFacts> {
    let mut lines = src.lines();
    if lines.next()?.trim() != "// world:" {
        return None;
    }
    let rows: Vec<&str> =
        lines.map_while(|l| l.strip_prefix("// ")).filter(|l| !l.is_empty()).collect();
    let (width, height) = (rows.first()?.len(), rows.len());
    let at = |x: usize, y: usize| rows[height - 1 - y].as_bytes()[x];
    let cell = |x: usize, y: usize| y * width + x;
    let mut free = vec![false; width * height];
    let mut queue = Vec::new();
    for y in 0..height {
        for x in 0..width {
            free[cell(x, y)] = at(x, y) != b'#';
            if at(x, y) == b'S' {
                queue.push((x, y));
            }
        }
    }
    if queue.is_empty() {
        queue = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).collect();
        queue.retain(|&(x, y)| free[cell(x, y)]);
    }
    let mut reachable = vec![false; width * height];
    while let Some((x, y)) = queue.pop() {
        if std::mem::replace(&mut reachable[cell(x, y)], true) {
            continue;
        }
        let next = [(x + 1, y), (x, y + 1), (x.wrapping_sub(1), y), (x, y.wrapping_sub(1))];
        for (nx, ny) in next {
            if nx < width && ny < height && free[cell(nx, ny)] {
                queue.push((nx, ny));
            }
        }
    }
    Some(WorldFacts { label: "world `fixture`".into(), width, height, free, reachable })
}

/// `(file name, source)` of every `.hstl` file in `tests/fixtures/<dir>`, sorted.
fn fixtures(dir: &str) -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(dir);
    let mut out: Vec<(String, String)> = std::fs::read_dir(&root)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", root.display()))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "hstl"))
        .map(|p| {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            let src = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
            (name, src)
        })
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no fixtures in {}", root.display());
    out
}

#[test]
fn invalid_fixtures_render() {
    for (name, src) in fixtures("invalid") {
        let checked = check(&src);
        let rendered = render_plain(&format!("invalid/{name}"), &src, &checked.diagnostics);
        insta::assert_snapshot!(name.trim_end_matches(".hstl"), rendered);
    }
}

#[test]
fn invalid_fixtures_produce_their_code() {
    for (name, src) in fixtures("invalid") {
        let code = &name[..7];
        let checked = check(&src);
        assert!(
            checked.diagnostics.iter().any(|d| d.code == code),
            "{name} does not produce {code}: {:#?}",
            checked.diagnostics
        );
    }
}

#[test]
fn every_code_has_an_entry_and_a_fixture() {
    let with_fixture: BTreeSet<String> =
        fixtures("invalid").into_iter().map(|(n, _)| n[..7].to_string()).collect();
    for c in codes::CODES {
        assert!(with_fixture.contains(c.code), "{} has no fixture", c.code);
        assert!(!c.summary.ends_with('.'), "{} summary ends with a period", c.code);
        assert!(c.explanation.contains("Fix"), "{} explanation names no fix", c.code);
        assert_eq!(codes::lookup(&c.code.to_lowercase()), Some(c));
        assert_eq!(codes::lookup(c.code), Some(c));
    }
    // `lookup` binary-searches the exact spelling.
    assert!(codes::CODES.windows(2).all(|w| w[0].code < w[1].code), "CODES is not sorted");
    for (name, src) in fixtures("invalid").into_iter().chain(fixtures("valid")) {
        for d in check(&src).diagnostics {
            let info = codes::lookup(d.code)
                .unwrap_or_else(|| panic!("{name}: {} not in the table", d.code));
            if d.code != "HSTL024" {
                assert_eq!(info.severity, d.severity, "{name}: {}", d.code);
            }
            assert!(!d.message.ends_with('.'), "{name}: message ends with a period: {}", d.message);
            assert!(
                d.range.end <= src.len() && d.range.start <= d.range.end,
                "{name}: {:?}",
                d.range
            );
        }
    }
}

/// A map adds diagnostics and nothing else: the checked spec, and so the learner, is the
/// same from the macro (no map) and the CLI (a map). `preset: auto` decides whether to plan
/// on the map without its walls.
#[test]
fn a_map_changes_only_the_diagnostics() {
    let mut with_maps = 0;
    let all = fixtures("valid").into_iter().chain(fixtures("invalid"));
    for (name, src) in all.filter(|(_, s)| world_of(s).is_some()) {
        let (in_world, alone) = (check(&src), hstl_lang::check(&src));
        assert_eq!(in_world.specs.len(), alone.specs.len(), "{name}");
        for (a, b) in in_world.specs.iter().zip(&alone.specs) {
            assert_eq!(a.learn.plan, b.learn.plan, "{name}: `plan` differs with the map");
            assert_eq!(a, b, "{name}: the checked spec differs with the map");
        }
        with_maps += 1;
    }
    assert!(with_maps > 0, "no fixture draws a map");
}

#[test]
fn valid_fixtures_check_without_errors() {
    for (name, src) in fixtures("valid") {
        let checked = check(&src);
        let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.is_error()).collect();
        assert!(errors.is_empty(), "{name}: {}", render_plain(&name, &src, &checked.diagnostics));
        let mut summary = String::new();
        for spec in &checked.specs {
            summarise(&mut summary, spec, &src);
        }
        summary.push_str(&render_plain(&name, &src, &checked.diagnostics));
        insta::assert_snapshot!(format!("valid_{}", name.trim_end_matches(".hstl")), summary);
    }
}

fn text(src: &str, f: &CFormula) -> String {
    let t = src.get(f.range.clone()).unwrap_or("?");
    // A default `init: true` carries the option name's range, and so does the `init: !A`
    // that `preset: auto` fills in.
    match &f.kind {
        CFormulaKind::True if t != "true" => "true (default)".into(),
        CFormulaKind::Not(inner) if !t.starts_with('!') => match &inner.kind {
            // `keep_clear`'s reach, `!(R1 || R2)`, carries the first region's range.
            CFormulaKind::Or(parts) => {
                let parts: Vec<String> = parts.iter().map(|p| text(src, p)).collect();
                format!("!({}) (preset)", parts.join(" || "))
            }
            _ => format!("!{t} (preset)"),
        },
        _ => t.to_string(),
    }
}

/// A readable summary of a checked spec for snapshots.
fn summarise(out: &mut String, spec: &CheckedSpec, src: &str) {
    let _ = writeln!(out, "spec {} (doc: {:?})", spec.name, spec.doc);
    if let Some(w) = &spec.world {
        let _ = writeln!(out, "  world {:?} at {}", w.name, &src[w.range.clone()]);
    }
    for v in &spec.state_vars {
        let dom = match v.domain {
            Domain::Unbounded => "unbounded".to_string(),
            Domain::Int { lo, hi } => format!("{lo}..={hi}"),
            Domain::Float { lo, hi, inclusive } => {
                format!("{lo}{}{hi}", if inclusive { "..=" } else { ".." })
            }
        };
        let _ = writeln!(out, "  var {}: {:?} in {dom} (doc: {:?})", v.name, v.ty, v.doc);
    }
    if let Some(t) = &spec.time {
        let mut bounds = Vec::new();
        let mut stack: Vec<&CFormula> = spec.lets.iter().map(|l| &l.formula).collect();
        stack.extend(spec.task.as_ref().map(|t| &t.formula));
        while let Some(f) = stack.pop() {
            if let CFormulaKind::Always(i, _)
            | CFormulaKind::Eventually(i, _)
            | CFormulaKind::Once(i, _)
            | CFormulaKind::Historically(i, _)
            | CFormulaKind::Until(i, ..)
            | CFormulaKind::Since(i, ..) = &f.kind
            {
                let end = match i.end {
                    Bound::Unbounded => String::new(),
                    Bound::Inclusive(b) => format!("={}", spec.bound_text(b)),
                    Bound::Exclusive(b) => spec.bound_text(b),
                };
                bounds.push(format!(
                    "[{}..{end}] ({:?}..{:?})",
                    spec.bound_text(i.start),
                    i.start,
                    i.end
                ));
            }
            stack.extend(f.operands());
        }
        let _ = writeln!(
            out,
            "  dense time: `{}` (doc: {:?}), {} decimals; intervals {}",
            t.name,
            t.doc,
            spec.time_decimals,
            bounds.join(" ")
        );
    }
    for l in &spec.lets {
        let _ = writeln!(
            out,
            "  let {}: {:?}, used {} = {}",
            l.name,
            l.kind,
            l.used,
            text(src, &l.formula)
        );
    }
    if let Some(t) = &spec.task {
        let _ = writeln!(out, "  task {}", text(src, &t.formula));
    }
    match spec.persistent_conjuncts(src) {
        Some(cs) => {
            let parts: Vec<String> =
                cs.iter().map(|c| format!("({}, {})", c.name, c.steps)).collect();
            let _ = writeln!(out, "  persistent: {}", parts.join(" "));
        }
        None => {
            let _ = writeln!(out, "  persistent: no");
        }
    }
    for p in &spec.primitives {
        let term = match &p.terminate {
            Terminate::Argmax => "argmax".to_string(),
            Terminate::Formula(f) => text(src, f),
        };
        let avoid = p.avoid.as_ref().map_or(String::new(), |a| format!(", avoid {}", text(src, a)));
        let _ = writeln!(
            out,
            "  option {}: reach {}, init {}, terminate {term}{avoid}",
            p.name,
            text(src, &p.reach),
            text(src, &p.init)
        );
    }
    if let Some(e) = &spec.preset_expansion {
        let _ = writeln!(out, "  preset: auto expands to:\n    {}", e.replace('\n', "\n    "));
    }
    let set: Vec<String> = spec
        .options
        .iter()
        .map(|o| {
            let legs: Vec<&str> =
                o.sequence.iter().map(|&i| spec.primitives[i].name.as_str()).collect();
            format!("{}=[{}]", o.name, legs.join(","))
        })
        .collect();
    let _ = writeln!(out, "  options ({}): {}", set.len(), set.join(" "));
    let _ = writeln!(out, "  learn {:?}", spec.learn);
}

#[test]
fn recovery_reports_syntax_and_semantic_errors_of_different_items() {
    let src = "spec S {\n    state { x: int in 0..=9 }\n    let A = x > ;\n    let B = q > 1;\n    task always[0..] eventually[0..10] B;\n}\n";
    let checked = check(src);
    let codes: Vec<&str> = checked.diagnostics.iter().map(|d| d.code).collect();
    assert!(codes.contains(&"HSTL001"), "{codes:?}");
    assert!(codes.contains(&"HSTL002"), "{codes:?}");
    let syntax = checked.diagnostics.iter().find(|d| d.code == "HSTL001").map(|d| d.range.clone());
    assert_eq!(syntax.map(|r| &src[r]), Some(";"));
    let unknown = checked.diagnostics.iter().find(|d| d.code == "HSTL002").map(|d| d.range.clone());
    assert_eq!(unknown.map(|r| &src[r]), Some("q"));
}

#[test]
fn diagnostics_are_deduplicated_and_capped() {
    let (_, src) = fixtures("invalid")
        .into_iter()
        .find(|(n, _)| n.starts_with("HSTL024"))
        .expect("the HSTL024 fixture");
    let d = check(&src).diagnostics;
    assert_eq!(d.len(), hstl_lang::check::MAX_DIAGNOSTICS + 1);
    assert_eq!(d.last().map(|d| d.code), Some("HSTL024"));
    let unique: BTreeSet<_> =
        d.iter().map(|d| (d.range.start, d.range.end, d.code, d.message.clone())).collect();
    assert_eq!(unique.len(), d.len());
}

#[test]
fn every_code_written_in_the_sources_is_in_the_table() {
    let src_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = BTreeSet::new();
    for entry in std::fs::read_dir(&src_dir).expect("src").filter_map(Result::ok) {
        let text = std::fs::read_to_string(entry.path()).unwrap_or_default();
        for (i, _) in text.match_indices("\"HSTL") {
            if let Some(code) = text.get(i + 1..i + 8) {
                found.insert(code.to_string());
            }
        }
    }
    assert!(found.len() >= 20, "{found:?}");
    for code in found {
        assert!(codes::lookup(&code).is_some(), "{code} is emitted but not in codes::CODES");
    }
}
