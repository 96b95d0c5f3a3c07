//! Plane world files (`kind = "plane"`): one test per kind of error, each with its exact
//! message and the text its span covers, and grid files read exactly as before.

use hstl_runtime::world::{AnyWorld, WorldError};
use hstl_runtime::{GridWorld, Obstacle, PlaneWorld, World};

const BASE: &str = "kind = \"plane\"\nx = [0, 20]\ny = [0, 10]\nstep = 0.5\nheadings = 4\n";

/// The error of `text`: its message, the text its span covers, and its help.
fn error(text: &str) -> (String, String, String) {
    let e: WorldError = match AnyWorld::from_toml(text, "w") {
        Ok(_) => panic!("read without error:\n{text}"),
        Err(e) => e,
    };
    assert!(!e.message.ends_with('.') && !e.help.is_empty(), "{e:?}");
    let span = e.span.clone().expect("an error with a span");
    (e.message, text[span].to_string(), e.help)
}

/// `BASE` with `key = value` replaced or added.
fn with(key: &str, value: &str) -> String {
    let mut lines: Vec<String> =
        BASE.lines().filter(|l| !l.starts_with(&format!("{key} ="))).map(String::from).collect();
    lines.push(format!("{key} = {value}"));
    lines.join("\n") + "\n"
}

fn without(key: &str) -> String {
    BASE.lines().filter(|l| !l.starts_with(&format!("{key} ="))).map(|l| format!("{l}\n")).collect()
}

fn check(text: &str, message: &str, at: &str) {
    let (m, a, _) = error(text);
    assert_eq!((m.as_str(), a.as_str()), (message, at), "in\n{text}");
}

#[test]
fn a_plane_file_reads_with_defaults() {
    let AnyWorld::Plane(w) = AnyWorld::from_toml(BASE, "field").unwrap() else { panic!() };
    assert_eq!(w.name(), "field");
    assert_eq!(w.extent(), ([0.0, 20.0], [0.0, 10.0]));
    assert_eq!((w.step_length(), w.headings(), w.slip(), w.noise()), (0.5, 4, 0.0, 0.0));
    assert_eq!(w.start(), [0.0, 0.0, 20.0, 10.0]);
    let yard = PlaneWorld::from_toml(include_str!("data/yard.toml"), "ignored").unwrap();
    assert_eq!(yard.name(), "yard");
    assert_eq!(
        yard.obstacles(),
        [
            Obstacle::Circle { cx: 10.0, cy: 5.0, r: 1.5 },
            Obstacle::Rect { x0: 4.0, y0: 0.0, x1: 5.0, y1: 6.0 }
        ]
    );
    // Integers and floats alike; a whole-number float for the headings.
    let w = PlaneWorld::from_toml(&with("headings", "8.0"), "w").unwrap();
    assert_eq!(w.headings(), 8);
}

#[test]
fn the_kind_decides_the_reader() {
    check("kind = \"hex\"\n", "unknown world kind `hex`", "\"hex\"");
    check("kind = 3\n", "kind must be a string, not a number", "3");
    // A grid reader refuses a plane file, at its kind, and a plane reader a grid file.
    let e = GridWorld::from_toml(BASE, "w").unwrap_err();
    assert_eq!(
        e.message,
        "this is a plane world (`kind = \"plane\"`); only a grid world can be used here"
    );
    assert_eq!(&BASE[e.span.unwrap()], "\"plane\"");
    let grid = "kind = \"grid\"\nslip = 0.1\nmap = '''\n..\n'''\n";
    let e = PlaneWorld::from_toml(grid, "w").unwrap_err();
    assert_eq!(e.message, "this is a grid world; only a plane world can be used here");
    // `kind = "grid"` reads as no kind at all.
    let plain = GridWorld::from_toml("slip = 0.1\nmap = '''\n..\n'''\n", "w").unwrap();
    assert_eq!(GridWorld::from_toml(grid, "w").unwrap(), plain);
    assert_eq!(AnyWorld::from_toml(grid, "w").unwrap(), AnyWorld::Grid(plain));
}

#[test]
fn grid_files_keep_their_messages() {
    // As hstlc's snapshots pin them: `kind` is not among the keys a grid lists.
    let text = "slip = 0.3\nwidth = 3\nmap = '''\n..\n'''\n";
    let e = GridWorld::from_toml(text, "w").unwrap_err();
    assert_eq!(e.message, "unknown field `width`, expected one of `name`, `slip`, `map`");
    assert_eq!(&text[e.span.unwrap()], "width");
    assert_eq!(e.help, "a world file has only the keys `name`, `slip` and `map`");
    let e = GridWorld::from_toml("kind = \"grid\"\nmap = '''\n.x\n'''\n", "w").unwrap_err();
    assert_eq!(e.message, "unknown character `x` in the map");
}

#[test]
fn toml_syntax_errors() {
    let (m, _, help) = error("kind = \"plane\"\nx = [0, 20\n");
    assert_eq!(m, "unclosed array, expected `]`");
    assert!(help.contains("TOML"));
}

#[test]
fn unknown_keys() {
    let (m, at, help) = error(&with("map", "'x'"));
    assert_eq!(
        m,
        "unknown field `map`, expected one of `name`, `kind`, `x`, `y`, `step`, `headings`, \
         `slip`, `noise`, `obstacles`, `start`"
    );
    assert_eq!(at, "map");
    assert!(help.starts_with("a plane world file has only the keys"));
}

#[test]
fn missing_keys_point_at_the_kind() {
    check(&without("x"), "the plane world has no `x`", "\"plane\"");
    check(&without("y"), "the plane world has no `y`", "\"plane\"");
    check(&without("step"), "the plane world has no `step`", "\"plane\"");
    check(&without("headings"), "the plane world has no `headings`", "\"plane\"");
}

#[test]
fn values_of_the_wrong_type() {
    check(&with("x", "\"wide\""), "x must be two numbers [lo, hi], not a string", "\"wide\"");
    check(&with("step", "\"far\""), "step must be a number, not a string", "\"far\"");
    check(&with("slip", "[0.1]"), "slip must be a number, not a list", "[0.1]");
    check(&with("noise", "{ sd = 1 }"), "noise must be a number, not a table", "{ sd = 1 }");
    check(&with("headings", "true"), "headings must be a whole number, not a boolean", "true");
    check(&with("name", "3"), "name must be a string, not a number", "3");
    check(&with("noise", "1979-05-27"), "a date is not a value of a plane world", "1979-05-27");
}

#[test]
fn extents() {
    check(&with("x", "[0, 20, 30]"), "x must be two numbers [lo, hi], not 3", "[0, 20, 30]");
    check(
        &with("y", "[0, \"a\"]"),
        "y must be two numbers [lo, hi], not a list holding a string",
        "\"a\"",
    );
    check(&with("x", "[0, inf]"), "x = [0, inf]: the extent's bounds must be finite", "inf");
    check(&with("y", "[nan, 1]"), "y = [NaN, 1]: the extent's bounds must be finite", "nan");
    check(
        &with("x", "[5, 5]"),
        "x = [5, 5]: the lower bound must be less than the upper",
        "[5, 5]",
    );
    check(
        &with("y", "[3, -3]"),
        "y = [3, -3]: the lower bound must be less than the upper",
        "[3, -3]",
    );
}

#[test]
fn steps() {
    check(&with("step", "0"), "step = 0 is not a positive finite number", "0");
    check(&with("step", "-0.5"), "step = -0.5 is not a positive finite number", "-0.5");
    check(&with("step", "nan"), "step = NaN is not a positive finite number", "nan");
    check(&with("step", "inf"), "step = inf is not a positive finite number", "inf");
}

#[test]
fn headings() {
    for (v, shown) in [("2", "2"), ("65", "65"), ("-3", "-3"), ("4.5", "4.5"), ("1e300", "1e300")] {
        check(
            &with("headings", v),
            &format!("headings = {shown} is not a whole number from 3 to 64"),
            v,
        );
    }
}

#[test]
fn slip_and_noise() {
    check(&with("slip", "1.5"), "slip = 1.5 is not a probability in [0, 1]", "1.5");
    check(&with("slip", "-0.1"), "slip = -0.1 is not a probability in [0, 1]", "-0.1");
    check(&with("noise", "-0.1"), "noise = -0.1 is not a non-negative finite number", "-0.1");
    check(&with("noise", "inf"), "noise = inf is not a non-negative finite number", "inf");
}

#[test]
fn obstacle_shapes() {
    let o = |list: &str| with("obstacles", list);
    check(&o("3"), "obstacles must be a list of circles and rectangles, not a number", "3");
    check(
        &o("[3]"),
        "an obstacle must be a table such as `{ circle = [cx, cy, r] }`, not a number",
        "3",
    );
    check(&o("[{}]"), "an obstacle must be a circle or a rect, not an empty table", "{}");
    let two = "{ circle = [1, 1, 1], rect = [0, 0, 1, 1] }";
    check(&o(&format!("[{two}]")), "an obstacle has one key, `circle` or `rect`, not 2", two);
    check(
        &o("[{ square = [1, 1, 1] }]"),
        "unknown obstacle `square`: an obstacle is a `circle` or a `rect`",
        "square",
    );
    check(
        &o("[{ circle = [1, 1] }]"),
        "a circle must be three numbers [cx, cy, r], not 2",
        "[1, 1]",
    );
    check(&o("[{ rect = 5 }]"), "a rect must be four numbers [x0, y0, x1, y1], not a number", "5");
}

#[test]
fn obstacle_numbers() {
    let o = |list: &str| with("obstacles", list);
    // The second obstacle is the bad one: the span is its number or its list.
    check(
        &o("[{ circle = [1, 1, 1] }, { circle = [15, 5, 0] }]"),
        "circle [15, 5, 0]: its radius must be positive",
        "0",
    );
    check(&o("[{ circle = [1, 1, -2] }]"), "circle [1, 1, -2]: its radius must be positive", "-2");
    check(
        &o("[{ circle = [1, inf, 1] }]"),
        "circle [1, inf, 1]: its numbers must be finite",
        "inf",
    );
    check(
        &o("[{ rect = [4, 0, 4, 6] }]"),
        "rect [4, 0, 4, 6] is empty: x0 must be less than x1",
        "[4, 0, 4, 6]",
    );
    check(
        &o("[{ rect = [4, 6, 5, 6] }]"),
        "rect [4, 6, 5, 6] is empty: y0 must be less than y1",
        "[4, 6, 5, 6]",
    );
    check(
        &o("[{ rect = [4, 0, nan, 6] }]"),
        "rect [4, 0, NaN, 6]: its numbers must be finite",
        "nan",
    );
}

#[test]
fn too_many_obstacles_are_refused_by_count() {
    let list = format!("[{}]", vec!["{ circle = [1, 1, 0.1] }"; 1500].join(", "));
    let (m, at, _) = error(&with("obstacles", &list));
    assert_eq!(m, "the world has 1500 obstacles, more than the 1024 a world may have");
    assert_eq!(at, list);
    // 1024 is allowed.
    let list = format!("[{}]", vec!["{ circle = [1, 1, 0.1] }"; 1024].join(", "));
    assert_eq!(
        PlaneWorld::from_toml(&with("obstacles", &list), "w").unwrap().obstacles().len(),
        1024
    );
}

#[test]
fn start_rectangles() {
    check(
        &with("start", "[0, 0, 2]"),
        "start must be four numbers [x0, y0, x1, y1], not 3",
        "[0, 0, 2]",
    );
    check(
        &with("start", "[0, 0, inf, 2]"),
        "start = [0, 0, inf, 2]: its numbers must be finite",
        "inf",
    );
    check(
        &with("start", "[2, 0, 1, 2]"),
        "start = [2, 0, 1, 2]: x0 must not exceed x1",
        "[2, 0, 1, 2]",
    );
    check(
        &with("start", "[0, 3, 1, 2]"),
        "start = [0, 3, 1, 2]: y0 must not exceed y1",
        "[0, 3, 1, 2]",
    );
    check(
        &with("start", "[30, 0, 40, 2]"),
        "start = [30, 0, 40, 2] lies outside the extent x in [0, 20], y in [0, 10]",
        "[30, 0, 40, 2]",
    );
    // Clipped to the extent; a rectangle that meets it only on its edge is a segment.
    let w = PlaneWorld::from_toml(&with("start", "[-5, -5, 2, 2]"), "w").unwrap();
    assert_eq!(w.start(), [0.0, 0.0, 2.0, 2.0]);
    let w = PlaneWorld::from_toml(&with("start", "[20, 2, 25, 4]"), "w").unwrap();
    assert_eq!(w.start(), [20.0, 2.0, 20.0, 4.0]);
}

#[test]
fn start_rectangles_need_a_free_part() {
    let text = format!("{BASE}start = [0, 0, 2, 2]\nobstacles = [{{ rect = [-1, -1, 3, 3] }}]\n");
    check(
        &text,
        "no position in start = [0, 0, 2, 2] is free: obstacles cover all of it",
        "[0, 0, 2, 2]",
    );
    // Without a start rectangle, the whole extent; the error points at the obstacles.
    let list = "[{ circle = [10, 5, 30] }]";
    check(
        &with("obstacles", list),
        "no position in the extent is free: obstacles cover all of it",
        list,
    );
    // Two rectangles that together cover it, overlapping in a sliver: no single one
    // covers the boxes along their seam, so this is "found", not proved.
    let text = format!(
        "{BASE}start = [0, 0, 2, 2]\nobstacles = [{{ rect = [0, 0, 2, 1.99999999] }}, {{ rect = [0, 1.99999, 2, 2] }}]\n"
    );
    check(
        &text,
        "no free position was found in start = [0, 0, 2, 2]: obstacles cover nearly all of it",
        "[0, 0, 2, 2]",
    );
    // A free sliver a millionth of the rectangle wide: thinner than the boxes the budget
    // reaches, so no free position is found.
    let text = format!(
        "{BASE}start = [0, 0, 2, 2]\nobstacles = [{{ rect = [-1, -1, 0.999999, 3] }}, {{ rect = [1.000001, -1, 3, 3] }}]\n"
    );
    check(
        &text,
        "no free position was found in start = [0, 0, 2, 2]: obstacles cover nearly all of it",
        "[0, 0, 2, 2]",
    );
    // A free corner of 1/40000 of the extent is found, and is too small to start from.
    let text = "kind = \"plane\"\nx = [0, 100]\ny = [0, 100]\nstep = 1\nheadings = 4\n\
                obstacles = [{ rect = [0.5, -1, 101, 101] }, { rect = [-1, 0.5, 101, 101] }]\n";
    let (m, at, help) = error(text);
    assert_eq!(
        m,
        "the free part of the extent is too small to start from: less than 1/10000 of it was found free"
    );
    assert_eq!(at, "[{ rect = [0.5, -1, 101, 101] }, { rect = [-1, 0.5, 101, 101] }]");
    assert!(help.starts_with("move the start rectangle"));
    // A point start on an obstacle's edge has no free part; beside it, it starts there.
    let on = format!("{BASE}start = [3, 3, 3, 3]\nobstacles = [{{ circle = [4, 3, 1] }}]\n");
    check(
        &on,
        "no position in start = [3, 3, 3, 3] is free: obstacles cover all of it",
        "[3, 3, 3, 3]",
    );
    let beside = on.replace("[3, 3, 3, 3]", "[2.5, 3, 2.5, 3]");
    assert_eq!(PlaneWorld::from_toml(&beside, "w").unwrap().start(), [2.5, 3.0, 2.5, 3.0]);
}

#[test]
fn names() {
    check(&with("name", "\"\""), "the world's name must hold 1 to 200 characters", "\"\"");
    let w = PlaneWorld::from_toml(&with("name", "\"yard\""), "w").unwrap();
    assert_eq!(w.name(), "yard");
}
