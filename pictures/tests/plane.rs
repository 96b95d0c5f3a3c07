//! Plane pictures drawn from small data: the SVG parses and shows what a user relies on (one
//! arrow per lattice point, one map per memory slice, the run's path, titles and legend
//! entries); bad input is an error, never a panic.

use hstl_pictures::{
    Arrow, MAX_ARROWS, MAX_RASTER_CELLS, Outcome, Plane, PlaneRegion, PlaneSlice, PlaneStep,
    Raster, RegionKind, Shape, plane_flat_policy, plane_options_policy, plane_sample_run,
};
use roxmltree::{Document, Node};

/// Fill of arrows (and all text); arrows are the 7-point polygons of this colour.
const INK: &str = "#222222";

fn parse(svg: &str) -> Document<'_> {
    let doc = Document::parse(svg).unwrap_or_else(|e| panic!("SVG does not parse: {e}\n{svg}"));
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc
}

fn elements<'a, 'i>(doc: &'a Document<'i>, tag: &str) -> Vec<Node<'a, 'i>> {
    doc.descendants().filter(|n| n.is_element() && n.tag_name().name() == tag).collect()
}

fn texts(doc: &Document<'_>) -> Vec<String> {
    elements(doc, "text").iter().map(|n| n.text().unwrap_or("").trim().to_owned()).collect()
}

fn has_text(doc: &Document<'_>, wanted: &str) -> bool {
    texts(doc).iter().any(|t| t == wanted)
}

fn points(node: &Node<'_, '_>) -> Vec<(f64, f64)> {
    node.attribute("points")
        .unwrap_or("")
        .split_whitespace()
        .map(|pair| {
            let (x, y) = pair.split_once(',').expect("points are x,y pairs");
            (x.parse().expect("x is a number"), y.parse().expect("y is a number"))
        })
        .collect()
}

/// The arrows: 7-point polygons in ink, as their screen direction (tail to tip).
fn arrows(doc: &Document<'_>) -> Vec<(f64, f64)> {
    elements(doc, "polygon")
        .iter()
        .filter(|n| n.attribute("fill") == Some(INK))
        .map(points)
        .filter(|p| p.len() == 7)
        .map(|p| {
            let tail = ((p[0].0 + p[6].0) / 2.0, (p[0].1 + p[6].1) / 2.0);
            (p[3].0 - tail.0, p[3].1 - tail.1)
        })
        .collect()
}

fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| (*s).to_owned()).collect()
}

/// `paper-plane`'s extent with the corner regions of a patrol, one round obstacle and one
/// square one, sampled 56 x 56.
fn yard() -> Plane {
    let corner = |name: &str, f: fn(f64, f64) -> bool| {
        let plane = Plane::new([0.0, 14.0], [0.0, 14.0]);
        PlaneRegion {
            name: name.into(),
            kind: RegionKind::Reach,
            holds: Raster::from_fn(56, 56, |i, j| {
                let (x, y) = plane.centre(56, 56, i, j);
                f(x, y)
            })
            .expect("raster"),
        }
    };
    let mut plane = Plane::new([0.0, 14.0], [0.0, 14.0]);
    plane.obstacles = vec![
        Shape::Circle { cx: 7.0, cy: 7.0, r: 1.5 },
        Shape::Rect { x0: 10.0, y0: -1.0, x1: 11.0, y1: 4.0 },
    ];
    plane.start = Some([0.0, 0.0, 2.0, 2.0]);
    plane.regions =
        vec![corner("A", |x, y| x < 3.0 && y > 11.0), corner("B", |x, y| x > 11.0 && y < 3.0)];
    plane
}

fn dump(name: &str, svg: &str) {
    if let Some(dir) = std::env::var_os("HSTL_PICTURES_DUMP") {
        std::fs::write(std::path::Path::new(&dir).join(name), svg).expect("dump");
    }
}

#[test]
fn flat_policy_draws_one_arrow_per_lattice_point_the_way_it_points() {
    let plane = yard();
    let lattice = plane.lattice(14, 14).expect("lattice");
    let arrows_in: Vec<Arrow> = lattice
        .iter()
        .map(|&(x, y)| Arrow {
            x,
            y,
            direction: Some(if x < 7.0 { (0.0, 1.0) } else { (1.0, 0.0) }),
        })
        .collect();
    let terminate: Vec<(f64, f64)> =
        lattice.iter().copied().filter(|&(x, y)| x < 3.0 && y > 11.0).collect();
    let svg = plane_flat_policy(
        &plane,
        "Patrol: flat policy of option A\nseed 3",
        &arrows_in,
        &terminate,
    )
    .expect("draws");
    dump("plane_flat.svg", &svg);
    let doc = parse(&svg);
    let drawn = arrows(&doc);
    // One per lattice point, and the legend's.
    assert_eq!(drawn.len(), 14 * 14 + 1);
    // Up (screen y decreasing) on the left half, right on the other.
    let up = drawn.iter().filter(|(dx, dy)| *dy < 0.0 && dx.abs() < 1.0).count();
    let right = drawn.iter().filter(|(dx, dy)| *dx > 0.0 && dy.abs() < 1.0).count();
    assert_eq!((up, right), (7 * 14, 7 * 14 + 1));
    for wanted in [
        "Patrol: flat policy of option A",
        "seed 3",
        "greedy action",
        "terminates",
        "region to reach",
        "obstacle",
        "start area",
        "A",
        "B",
        "x",
        "y",
        "14",
    ] {
        assert!(has_text(&doc, wanted), "no text `{wanted}` in {:?}", texts(&doc));
    }
    assert!(!has_text(&doc, "action without a direction"));
}

#[test]
fn an_action_without_a_direction_is_a_ring_on_a_phase_plane() {
    let mut plane = Plane::new([-1.2, 0.6], [-0.07, 0.07]);
    plane.y_label = "v".into();
    plane.to_scale = false;
    let lattice = plane.lattice(6, 4).expect("lattice");
    let arrows_in: Vec<Arrow> = lattice
        .iter()
        .enumerate()
        .map(|(k, &(x, y))| Arrow {
            x,
            y,
            direction: match k % 3 {
                0 => Some((-1.0, 0.0)),
                1 => None,
                _ => Some((1.0, 0.0)),
            },
        })
        .collect();
    let svg = plane_flat_policy(&plane, "Car: flat policy of option Right", &arrows_in, &[])
        .expect("draws");
    dump("car_flat.svg", &svg);
    let doc = parse(&svg);
    // Two in three are arrows (and the legend's); the others rings.
    assert_eq!(arrows(&doc).len(), 16 + 1);
    assert!(has_text(&doc, "action without a direction"));
    assert!(has_text(&doc, "v") && has_text(&doc, "x"));
    assert!(has_text(&doc, "0.00") || has_text(&doc, "0.0"), "{:?}", texts(&doc));
    assert!(!has_text(&doc, "-0.00"));
}

#[test]
fn options_policy_draws_one_map_per_memory_slice_in_one_picture() {
    let plane = yard();
    let slice = |label: &str, pick: usize| PlaneSlice {
        label: label.into(),
        choices: Raster::from_fn(40, 40, |i, _| if i < 20 { Some(pick) } else { Some(1 - pick) })
            .expect("raster"),
    };
    let options = names(&["A", "B"]);
    let slices = [slice("one step after A", 1), slice("one step after B", 0)];
    let svg = plane_options_policy(&plane, "Patrol: options policy\nseed 3", &slices, &options)
        .expect("draws");
    dump("plane_options.svg", &svg);
    let doc = parse(&svg);
    for wanted in
        ["Patrol: options policy", "one step after A", "one step after B", "A", "B", "Option"]
    {
        assert!(has_text(&doc, wanted), "no text `{wanted}` in {:?}", texts(&doc));
    }
    assert!(!has_text(&doc, "no choice"));
    // One frame border (an unfilled ink rectangle as wide as a map) per map.
    let borders = elements(&doc, "rect")
        .iter()
        .filter(|n| n.attribute("stroke") == Some(INK) && n.attribute("fill") == Some("none"))
        .filter(|n| {
            n.attribute("width").and_then(|w| w.parse::<f64>().ok()).is_some_and(|w| w > 200.0)
        })
        .count();
    assert_eq!(borders, 2);
    // Both options' colours fill cells, in the palette's order.
    for colour in ["#E6194B", "#3CB44B"] {
        assert!(
            elements(&doc, "rect").iter().any(|n| n.attribute("fill") == Some(colour)),
            "no cell of {colour}"
        );
    }
    // Without memory: one map, no label; a cell without a choice is listed.
    let lone = PlaneSlice {
        label: String::new(),
        choices: Raster::from_fn(10, 10, |i, _| (i > 0).then_some(0)).expect("raster"),
    };
    let svg = plane_options_policy(&plane, "t", &[lone], &options).expect("draws");
    assert!(has_text(&parse(&svg), "no choice"));
}

#[test]
fn sample_run_draws_its_path_with_slips_blocked_moves_and_entries() {
    let plane = yard();
    let mut steps: Vec<PlaneStep> =
        (0..12).map(|k| PlaneStep::at(1.0, 1.0 + k as f64, Some(0))).collect();
    steps[3].outcome = Outcome::Slipped;
    steps[3].intended = Some((1.0, 5.0));
    steps[4].x = 1.3;
    // A blocked move: the next step stays.
    steps[6].outcome = Outcome::Blocked;
    steps[6].intended = Some((0.0, 7.0));
    steps[7].y = steps[6].y;
    steps[11].entered = vec![0];
    steps.push(PlaneStep { option: Some(1), ..PlaneStep::at(3.0, 12.0, Some(1)) });
    let options = names(&["A", "B"]);
    let svg =
        plane_sample_run(&plane, "Patrol: sample run 1\nseed 3", &steps, &options).expect("draws");
    dump("plane_run.svg", &svg);
    let doc = parse(&svg);
    for wanted in [
        "Patrol: sample run 1",
        "start",
        "end",
        "slip (dots: move chosen)",
        "blocked (dots: move chosen)",
        "enters a region",
        "12 moves, 1 slip, 1 blocked",
        "step",
        "A",
        "B",
    ] {
        assert!(has_text(&doc, wanted), "no text `{wanted}` in {:?}", texts(&doc));
    }
    // 11 moves that go somewhere (one is blocked), each a core line of 3 px over a casing.
    let cores = elements(&doc, "polyline")
        .iter()
        .filter(|n| n.attribute("stroke-width") == Some("3") && points(n).len() == 2)
        .filter(|n| n.attribute("stroke") != Some("#C01C28"))
        .count();
    assert_eq!(cores, 11);
    // Only the options the run uses are listed: here both.
    let one: Vec<PlaneStep> = steps[..3].to_vec();
    let svg = plane_sample_run(&plane, "t", &one, &options).expect("draws");
    let doc = parse(&svg);
    assert!(!has_text(&doc, "B") || texts(&doc).iter().filter(|t| *t == "B").count() == 1);
    assert!(!has_text(&doc, "slip (dots: move chosen)"));
}

#[test]
fn a_run_of_one_step_and_a_run_on_the_edge_still_draw() {
    let plane = yard();
    let svg = plane_sample_run(&plane, "t", &[PlaneStep::at(0.0, 0.0, None)], &[]).expect("draws");
    assert!(has_text(&parse(&svg), "0 moves, 0 slips, 0 blocked"));
    let edge = [PlaneStep::at(14.0, 14.0, None), PlaneStep::at(0.0, 14.0, None)];
    plane_sample_run(&plane, "t", &edge, &[]).expect("points on the extent's edge are inside");
}

#[test]
fn bad_input_is_an_error_with_a_clear_message() {
    let good = yard();
    let with = |f: &dyn Fn(&mut Plane)| {
        let mut p = good.clone();
        f(&mut p);
        p
    };
    let zero = with(&|p| p.x = [3.0, 3.0]);
    let nan = with(&|p| p.y = [0.0, f64::NAN]);
    let inf = with(&|p| p.x = [-f64::MAX, f64::MAX]);
    let circle = with(&|p| p.obstacles = vec![Shape::Circle { cx: 1.0, cy: 1.0, r: 0.0 }]);
    let start = with(&|p| p.start = Some([2.0, 0.0, 1.0, 1.0]));
    let short = with(&|p| p.regions[0].holds.values.pop().map_or((), |_| ()));
    let arrow = |x: f64, y: f64, direction| Arrow { x, y, direction };
    let one = |label: &str, raster: Raster<Option<usize>>| PlaneSlice {
        label: label.into(),
        choices: raster,
    };
    let many = vec![arrow(1.0, 1.0, None); MAX_ARROWS + 1];
    let options = names(&["A"]);
    let cases: Vec<(&str, hstl_pictures::Result<String>, &str)> = vec![
        ("zero extent", plane_flat_policy(&zero, "t", &[], &[]), "the extent along `x` is [3, 3]"),
        ("NaN extent", plane_flat_policy(&nan, "t", &[], &[]), "it must be finite and not empty"),
        ("overflowing extent", plane_flat_policy(&inf, "t", &[], &[]), "must be finite"),
        ("flat circle", plane_flat_policy(&circle, "t", &[], &[]), "obstacle 1"),
        ("start", plane_flat_policy(&start, "t", &[], &[]), "the start area"),
        ("short raster", plane_flat_policy(&short, "t", &[], &[]), "region `A` has 3135 values"),
        (
            "NaN arrow",
            plane_flat_policy(&good, "t", &[arrow(f64::NAN, 1.0, None)], &[]),
            "arrow (NaN, 1) is not a finite point",
        ),
        (
            "arrow outside",
            plane_flat_policy(&good, "t", &[arrow(15.0, 1.0, None)], &[]),
            "arrow (15, 1) is outside the extent [0, 14] x [0, 14]",
        ),
        (
            "zero direction",
            plane_flat_policy(&good, "t", &[arrow(1.0, 1.0, Some((0.0, 0.0)))], &[]),
            "which is no direction",
        ),
        (
            "infinite direction",
            plane_flat_policy(&good, "t", &[arrow(1.0, 1.0, Some((f64::INFINITY, 0.0)))], &[]),
            "which is no direction",
        ),
        ("too many arrows", plane_flat_policy(&good, "t", &many, &[]), "too many to draw"),
        (
            "termination outside",
            plane_flat_policy(&good, "t", &[], &[(0.0, -1.0)]),
            "termination point (0, -1) is outside",
        ),
        ("no slice", plane_options_policy(&good, "t", &[], &options), "give at least one slice"),
        (
            "empty raster",
            plane_options_policy(
                &good,
                "t",
                &[one("m", Raster { columns: 0, rows: 3, values: vec![] })],
                &options,
            ),
            "options map `m` is empty (0 x 3 cells)",
        ),
        (
            "huge raster",
            plane_options_policy(
                &good,
                "t",
                &[one("", Raster { columns: 4096, rows: 4096, values: vec![] })],
                &options,
            ),
            "too large to draw",
        ),
        (
            "option past the end",
            plane_options_policy(
                &good,
                "t",
                &[one("m", Raster { columns: 1, rows: 1, values: vec![Some(3)] })],
                &options,
            ),
            "options map `m` picks option 3, but there are 1 options",
        ),
        ("empty run", plane_sample_run(&good, "t", &[], &options), "at least one step"),
        (
            "NaN step",
            plane_sample_run(&good, "t", &[PlaneStep::at(1.0, f64::NAN, None)], &options),
            "step 0 at (1, NaN) is not a finite point",
        ),
        (
            "step outside",
            plane_sample_run(
                &good,
                "t",
                &[PlaneStep::at(1.0, 1.0, None), PlaneStep::at(1.0, 20.0, None)],
                &options,
            ),
            "step 1 at (1, 20) is outside",
        ),
        (
            "intended NaN",
            plane_sample_run(
                &good,
                "t",
                &[PlaneStep { intended: Some((f64::NAN, 0.0)), ..PlaneStep::at(1.0, 1.0, None) }],
                &options,
            ),
            "intended point (NaN, 0) is not finite",
        ),
        (
            "step option",
            plane_sample_run(&good, "t", &[PlaneStep::at(1.0, 1.0, Some(1))], &options),
            "step 0 runs option 1, but there are 1 options",
        ),
        (
            "entered region",
            plane_sample_run(
                &good,
                "t",
                &[PlaneStep { entered: vec![2], ..PlaneStep::at(1.0, 1.0, None) }],
                &options,
            ),
            "step 0 enters region 2, but the plane has 2 regions",
        ),
    ];
    for (name, result, expected) in cases {
        let error = result.expect_err(name);
        let message = error.to_string();
        assert!(message.contains(expected), "{name}: {message:?} lacks {expected:?}");
        assert!(!message.ends_with('.'), "{name}: {message:?} ends with a period");
    }
    // A lattice past the budget is refused before anything is allocated.
    let huge = good.lattice(MAX_RASTER_CELLS, 2).expect_err("too large");
    assert!(huge.to_string().contains("too large to draw"), "{huge}");
    assert!(Raster::from_fn(usize::MAX, usize::MAX, |_, _| 0u8).is_err());
}

#[test]
fn obstacles_outside_and_odd_names_still_draw() {
    let mut plane = yard();
    plane.obstacles.push(Shape::Circle { cx: 100.0, cy: 100.0, r: 1.0 });
    plane.obstacles.push(Shape::Rect { x0: -5.0, y0: -5.0, x1: 50.0, y1: 0.5 });
    plane.regions[0].name = "x < 3 && y > 11 \u{7}".into();
    plane.regions[1].kind = RegionKind::Avoid;
    plane.y_label = "velocity".into();
    let svg = plane_flat_policy(&plane, "odd", &[], &[]).expect("draws");
    let doc = parse(&svg);
    assert!(has_text(&doc, "region to avoid") && has_text(&doc, "velocity"));
    // An empty region is neither drawn nor listed.
    plane.regions[0].holds.values.iter_mut().for_each(|v| *v = false);
    plane.regions[1].holds.values.iter_mut().for_each(|v| *v = false);
    let doc_svg = plane_flat_policy(&plane, "odd", &[], &[]).expect("draws");
    let doc = parse(&doc_svg);
    assert!(!has_text(&doc, "region to reach") && !has_text(&doc, "region to avoid"));
}

#[test]
fn the_same_input_gives_the_same_picture() {
    let plane = yard();
    let steps = [PlaneStep::at(1.0, 1.0, Some(0)), PlaneStep::at(2.0, 1.5, Some(0))];
    let options = names(&["A"]);
    assert_eq!(
        plane_sample_run(&plane, "t", &steps, &options).unwrap(),
        plane_sample_run(&plane, "t", &steps, &options).unwrap()
    );
}
