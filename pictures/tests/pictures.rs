//! Pictures drawn from small data: the SVG parses and shows what it must; bad input errors.

use std::collections::{BTreeSet, HashMap};

use hstl_pictures::{
    Action, Cell, Grid, Region, flat_policy, learning_curve, options_policy, options_policy_slices,
    sample_run, sample_run_ordered,
};
use roxmltree::{Document, Node};

/// Fill of arrows (and all text); arrows are the 7-point polygons of this colour.
const INK: &str = "#222222";
/// Fill of termination dots.
const TERMINATE: &str = "#D62728";

fn region(name: &str, cells: &[(i64, i64)]) -> Region {
    Region { name: name.to_owned(), cells: cells.to_vec() }
}

fn small_grid() -> Grid {
    Grid {
        width: 4,
        height: 3,
        regions: vec![region("A", &[(0, 2), (1, 2)]), region("Base", &[(3, 0)])],
        walls: vec![],
        starts: vec![],
    }
}

fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| (*s).to_owned()).collect()
}

/// Parses the SVG and checks the document element, returning the parsed tree.
fn parse(svg: &str) -> Document<'_> {
    let doc = Document::parse(svg).unwrap_or_else(|e| panic!("SVG does not parse: {e}\n{svg}"));
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    doc
}

fn elements<'a, 'i>(doc: &'a Document<'i>, tag: &str) -> Vec<Node<'a, 'i>> {
    doc.descendants().filter(|n| n.is_element() && n.tag_name().name() == tag).collect()
}

/// The trimmed contents of every `<text>`.
fn texts(doc: &Document<'_>) -> Vec<String> {
    elements(doc, "text").iter().map(|n| n.text().unwrap_or("").trim().to_owned()).collect()
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

/// The arrows: 7-point polygons in ink, as (centre, direction).
fn arrows(doc: &Document<'_>) -> Vec<((f64, f64), Action)> {
    elements(doc, "polygon")
        .iter()
        .filter(|n| n.attribute("fill") == Some(INK))
        .map(points)
        .filter(|p| p.len() == 7)
        .map(|p| {
            let tail = ((p[0].0 + p[6].0) / 2.0, (p[0].1 + p[6].1) / 2.0);
            let tip = p[3];
            let (dx, dy) = (tip.0 - tail.0, tip.1 - tail.1);
            let action = if dx.abs() > dy.abs() {
                if dx > 0.0 { Action::Right } else { Action::Left }
            } else if dy > 0.0 {
                // Pixels grow downwards.
                Action::Down
            } else {
                Action::Up
            };
            (((tail.0 + tip.0) / 2.0, (tail.1 + tip.1) / 2.0), action)
        })
        .collect()
}

/// Index of `value` among the distinct sorted values, where values a few pixels apart
/// (rounding) count as one.
fn rank(values: &[f64], value: f64) -> i64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mut index = 0;
    for pair in sorted.windows(2) {
        if pair[1] > value + 3.0 {
            break;
        }
        if pair[1] - pair[0] > 3.0 {
            index += 1;
        }
    }
    index
}

fn count_fill(doc: &Document<'_>, tag: &str, fill: &str) -> usize {
    elements(doc, tag).iter().filter(|n| n.attribute("fill") == Some(fill)).count()
}

fn has_text(doc: &Document<'_>, wanted: &str) -> bool {
    texts(doc).iter().any(|t| t == wanted)
}

#[test]
fn flat_policy_draws_each_arrow_where_and_how_it_was_asked() {
    let grid = small_grid();
    let actions = [Action::Up, Action::Down, Action::Left, Action::Right, Action::Up];
    let cells: Vec<Cell> = (0..4)
        .flat_map(|x| (0..3).map(move |y| (x, y)))
        .enumerate()
        .map(|(i, (x, y))| Cell { x, y, action: actions[i % actions.len()] })
        .collect();
    let terminate = [(1, 1), (3, 2), (1, 1)];
    let svg = flat_policy(&grid, "Go to A", &cells, &terminate).expect("draws");
    let doc = parse(&svg);
    for wanted in ["Go to A", "A", "Base", "Legend", "region", "action taken", "terminates"] {
        assert!(has_text(&doc, wanted), "missing text {wanted:?} in {:?}", texts(&doc));
    }
    // The legend shows one arrow and one dot besides those in the grid.
    let drawn = arrows(&doc);
    assert_eq!(drawn.len(), cells.len() + 1);
    let legend_x = drawn.iter().map(|((x, _), _)| *x).fold(f64::MIN, f64::max);
    let in_grid: Vec<_> = drawn.into_iter().filter(|((x, _), _)| *x < legend_x).collect();
    let xs: Vec<f64> = in_grid.iter().map(|((x, _), _)| *x).collect();
    let ys: Vec<f64> = in_grid.iter().map(|((_, y), _)| *y).collect();
    let height = grid.height as i64;
    let got: BTreeSet<(i64, i64, String)> = in_grid
        .iter()
        .map(|&((x, y), a)| (rank(&xs, x), height - 1 - rank(&ys, y), format!("{a:?}")))
        .collect();
    let expected: BTreeSet<(i64, i64, String)> =
        cells.iter().map(|c| (c.x, c.y, format!("{:?}", c.action))).collect();
    assert_eq!(got, expected);
    let unique_terminate: BTreeSet<_> = terminate.iter().collect();
    assert_eq!(count_fill(&doc, "circle", TERMINATE), unique_terminate.len() + 1);
}

#[test]
fn flat_policy_leaves_cells_without_action_empty() {
    let cells = [Cell { x: 2, y: 1, action: Action::Left }];
    let svg = flat_policy(&small_grid(), "One arrow", &cells, &[]).expect("draws");
    let doc = parse(&svg);
    assert_eq!(arrows(&doc).len(), cells.len() + 1);
    assert_eq!(count_fill(&doc, "circle", TERMINATE), 1);
}

#[test]
fn options_policy_colours_each_choice_and_lists_every_option() {
    let grid = small_grid();
    let order = names(&["go A", "go B", "unused"]);
    let choices: Vec<((i64, i64), String)> = vec![
        ((0, 0), "go A".into()),
        ((1, 0), "go B".into()),
        ((2, 0), "go A".into()),
        ((0, 1), "extra".into()),
    ];
    let svg = options_policy(&grid, "Options", &choices, &order).expect("draws");
    let doc = parse(&svg);
    // Eight of the twelve cells have no choice.
    for wanted in ["Options", "Option", "go A", "go B", "unused", "extra", "no choice", "A", "Base"]
    {
        assert!(has_text(&doc, wanted), "missing text {wanted:?} in {:?}", texts(&doc));
    }
    // Legend order: the given order, then the others as they first appear.
    let listed: Vec<String> =
        texts(&doc).into_iter().filter(|t| order.contains(t) || t == "extra").collect();
    assert_eq!(listed, names(&["go A", "go B", "unused", "extra"]));
    // Each option's colour fills its cells plus its legend swatch.
    let fills = rect_fills(&doc);
    let mut uses: HashMap<&str, usize> = HashMap::new();
    for (_, name) in &choices {
        *uses.entry(name.as_str()).or_default() += 1;
    }
    let counts: BTreeSet<usize> = uses.values().map(|n| n + 1).chain([1]).collect();
    let option_fills: BTreeSet<usize> =
        fills.values().copied().filter(|n| counts.contains(n)).collect();
    assert_eq!(option_fills, counts);
    let distinct_option_colours = fills.iter().filter(|(fill, _)| !is_neutral(fill)).count();
    assert_eq!(distinct_option_colours, order.len() + 1);
}

/// Rectangle fills (fully opaque only) and how often each occurs.
fn rect_fills(doc: &Document<'_>) -> HashMap<String, usize> {
    let mut fills = HashMap::new();
    for rect in elements(doc, "rect") {
        if rect.attribute("opacity") == Some("1")
            && let Some(fill) = rect.attribute("fill")
            && fill != "none"
        {
            *fills.entry(fill.to_owned()).or_default() += 1;
        }
    }
    fills
}

fn is_neutral(fill: &str) -> bool {
    ["#FFFFFF", "#222222", "#555555", "#CCCCCC"].contains(&fill)
}

#[test]
fn options_policy_tells_sixteen_options_apart() {
    let grid = Grid { width: 4, height: 4, regions: Vec::new(), walls: vec![], starts: vec![] };
    let order: Vec<String> = (0..16).map(|i| format!("option {i}")).collect();
    let choices: Vec<((i64, i64), String)> =
        (0..16).map(|i| ((i % 4, i / 4), order[i as usize].clone())).collect();
    let doc_text = options_policy(&grid, "Sixteen", &choices, &order).expect("draws");
    let doc = parse(&doc_text);
    let colours = rect_fills(&doc).into_keys().filter(|f| !is_neutral(f)).count();
    assert_eq!(colours, order.len());
    assert!(!has_text(&doc, "no choice"), "every cell has a choice");
}

#[test]
fn sample_run_and_options_policy_agree_on_colours_given_one_order() {
    let grid = small_grid();
    let order = names(&["go A", "go B", "go C"]);
    for (index, name) in order.iter().enumerate() {
        let choices = vec![((0, 0), name.clone())];
        let map = options_policy(&grid, "Map", &choices, &order).expect("draws");
        let steps = vec![((0, 0), name.clone()), ((1, 0), name.clone())];
        let run = sample_run_ordered(&grid, "Run", &steps, &order).expect("draws");
        let map_doc = parse(&map);
        let run_doc = parse(&run);
        let map_colours: BTreeSet<String> = rect_fills(&map_doc)
            .into_iter()
            .filter(|(f, n)| !is_neutral(f) && *n == 2)
            .map(|(f, _)| f)
            .collect();
        let run_colours = line_colours(&run_doc);
        assert_eq!(map_colours.len(), 1, "option {index}");
        assert!(
            run_colours.is_superset(&map_colours),
            "option {index}: {run_colours:?} vs {map_colours:?}"
        );
    }
}

/// Stroke colours of all lines that are not neutral.
fn line_colours(doc: &Document<'_>) -> BTreeSet<String> {
    elements(doc, "polyline")
        .iter()
        .filter_map(|n| n.attribute("stroke"))
        .filter(|s| !is_neutral(s))
        .map(str::to_owned)
        .collect()
}

#[test]
fn sample_run_draws_a_path_coloured_by_option_with_start_and_end() {
    let grid = small_grid();
    let steps: Vec<((i64, i64), String)> = vec![
        ((0, 0), "first".into()),
        ((1, 0), "first".into()),
        ((1, 0), "first".into()),
        ((1, 1), "second".into()),
        ((2, 1), "second".into()),
        ((3, 1), "first".into()),
        ((3, 2), "first".into()),
    ];
    let svg = sample_run(&grid, "Run 1", &steps).expect("draws");
    let doc = parse(&svg);
    let moves = steps.len() - 1;
    for wanted in
        ["Run 1", "first", "second", "start", "end", "A", "Base", &format!("{moves} moves")]
    {
        assert!(has_text(&doc, wanted), "missing text {wanted:?} in {:?}", texts(&doc));
    }
    assert_eq!(line_colours(&doc).len(), 2);
    // The path passes through every visited cell centre: its points span all rows and
    // columns visited.
    let path_points: Vec<(f64, f64)> = elements(&doc, "polyline")
        .iter()
        .filter(|n| n.attribute("stroke").is_some_and(|s| !is_neutral(s)))
        .flat_map(points)
        .collect();
    let columns: BTreeSet<i64> = steps.iter().map(|((x, _), _)| *x).collect();
    let xs: BTreeSet<i64> = path_points.iter().map(|(x, _)| (x / 10.0).round() as i64).collect();
    assert!(xs.len() >= columns.len(), "{xs:?} vs {columns:?}");
}

#[test]
fn a_run_of_one_step_has_no_path_but_still_start_and_end() {
    let svg = sample_run(&small_grid(), "Still", &[((2, 2), "wait".into())]).expect("draws");
    let doc = parse(&svg);
    assert!(has_text(&doc, "0 moves"));
    assert!(has_text(&doc, "start") && has_text(&doc, "end"));
    assert!(line_colours(&doc).len() <= 1, "only the legend line may be coloured");
}

#[test]
fn learning_curve_labels_axes_and_legend() {
    let seeds: Vec<Vec<f64>> =
        (0..3).map(|s| (0..50).map(|e| (e * (s + 1)) as f64 / 10.0).collect()).collect();
    let svg = learning_curve("Learning <curve> & more", &seeds, 5).expect("draws");
    let doc = parse(&svg);
    for wanted in [
        "Learning <curve> & more",
        "episode",
        "reward per episode",
        "mean of 3 seeds, moving average of 5 episodes",
        "lowest to highest seed",
    ] {
        assert!(has_text(&doc, wanted), "missing text {wanted:?} in {:?}", texts(&doc));
    }
}

#[test]
fn learning_curve_skips_non_finite_values_and_accepts_ragged_seeds() {
    let seeds = vec![vec![1.0, f64::NAN, 3.0, 4.0], vec![2.0, 2.5], vec![], vec![f64::INFINITY]];
    let svg = learning_curve("Ragged", &seeds, 1).expect("draws");
    let doc = parse(&svg);
    assert!(has_text(&doc, "2 non-finite values skipped"), "{:?}", texts(&doc));
    assert!(has_text(&doc, "mean of 4 seeds"));
}

#[test]
fn learning_curve_draws_degenerate_curves() {
    for seeds in [vec![vec![5.0]], vec![vec![2.0; 10]], vec![vec![0.0, f64::NAN, f64::NAN, 1.0]]] {
        let svg = learning_curve("Flat", &seeds, 0).expect("draws");
        let doc = parse(&svg);
        assert!(has_text(&doc, "reward"), "{seeds:?}: {:?}", texts(&doc));
    }
}

#[test]
fn long_curves_are_thinned() {
    let seed: Vec<f64> = (0..50_000).map(|e| (e % 97) as f64).collect();
    let svg = learning_curve("Long", &[seed], 100).expect("draws");
    let doc = parse(&svg);
    let longest = elements(&doc, "polyline").iter().map(|n| points(n).len()).max().unwrap_or(0);
    assert!(longest > 100 && longest <= 2001, "{longest} points");
}

#[test]
fn odd_text_is_escaped_and_control_characters_replaced() {
    let grid = Grid {
        width: 2,
        height: 2,
        regions: vec![region("<&\"'\u{1}>", &[(0, 0)])],
        walls: vec![],
        starts: vec![],
    };
    let svg = flat_policy(&grid, "a\u{0}b <tag> & \"quote\"", &[], &[]).expect("draws");
    let doc = parse(&svg);
    assert!(has_text(&doc, "a\u{fffd}b <tag> & \"quote\""), "{:?}", texts(&doc));
    assert!(has_text(&doc, "<&\"'\u{fffd}>"));
}

#[test]
fn irregular_and_empty_regions_are_drawn() {
    let grid = Grid {
        width: 5,
        height: 5,
        regions: vec![region("L", &[(0, 0), (0, 1), (0, 2), (1, 0), (2, 0)]), region("none", &[])],
        walls: vec![],
        starts: vec![],
    };
    let svg = flat_policy(&grid, "Shapes", &[], &[]).expect("draws");
    let doc = parse(&svg);
    assert!(has_text(&doc, "L"));
    assert!(!has_text(&doc, "none"), "an empty region has no label");
}

#[test]
fn bad_input_is_an_error_with_a_clear_message() {
    let grid = small_grid();
    let empty = Grid { width: 0, height: 3, regions: Vec::new(), walls: vec![], starts: vec![] };
    let huge =
        Grid { width: 10_000, height: 2, regions: Vec::new(), walls: vec![], starts: vec![] };
    let stray = Grid {
        width: 2,
        height: 2,
        regions: vec![region("R", &[(2, 0)])],
        walls: vec![],
        starts: vec![],
    };
    let up = |x, y| Cell { x, y, action: Action::Up };
    let cases: Vec<(&str, hstl_pictures::Result<String>, &str)> = vec![
        ("empty grid", flat_policy(&empty, "t", &[], &[]), "the grid is empty (0 x 3 cells)"),
        ("huge grid", options_policy(&huge, "t", &[], &[]), "too large to draw"),
        (
            "region outside",
            sample_run(&stray, "t", &[((0, 0), "o".into())]),
            "region `R` cell (2, 0) is outside the 2 x 2 grid",
        ),
        (
            "arrow outside",
            flat_policy(&grid, "t", &[up(4, 0)], &[]),
            "arrow cell (4, 0) is outside the 4 x 3 grid",
        ),
        (
            "negative arrow",
            flat_policy(&grid, "t", &[up(0, -1)], &[]),
            "arrow cell (0, -1) is outside",
        ),
        (
            "two actions",
            flat_policy(&grid, "t", &[up(1, 1), up(1, 1)], &[]),
            "cell (1, 1) has more than one action",
        ),
        (
            "termination outside",
            flat_policy(&grid, "t", &[], &[(0, 3)]),
            "termination cell (0, 3) is outside",
        ),
        (
            "choice outside",
            options_policy(&grid, "t", &[((-1, 0), "o".into())], &[]),
            "choice cell (-1, 0) is outside",
        ),
        (
            "two options",
            options_policy(&grid, "t", &[((0, 0), "a".into()), ((0, 0), "b".into())], &[]),
            "cell (0, 0) has more than one option",
        ),
        ("empty run", sample_run(&grid, "t", &[]), "a sample run needs at least one step"),
        (
            "step outside",
            sample_run(&grid, "t", &[((0, 0), "o".into()), ((0, 9), "o".into())]),
            "step cell (0, 9) is outside",
        ),
        ("no seeds", learning_curve("t", &[], 1), "a learning curve needs at least one seed"),
        ("empty seeds", learning_curve("t", &[vec![], vec![]], 1), "every seed is empty"),
        (
            "no finite reward",
            learning_curve("t", &[vec![f64::NAN, f64::INFINITY]], 3),
            "no reward is finite (all 2 values",
        ),
    ];
    for (name, result, expected) in cases {
        let error = result.expect_err(name);
        let message = error.to_string();
        assert!(message.contains(expected), "{name}: {message:?} lacks {expected:?}");
        assert!(!message.ends_with('.'), "{name}: {message:?} ends with a period");
    }
}

#[test]
fn the_same_input_gives_the_same_picture() {
    let grid = small_grid();
    let cells = [Cell { x: 0, y: 0, action: Action::Up }];
    let terminate = [(1, 1), (2, 2), (3, 0), (0, 2)];
    let first = flat_policy(&grid, "Same", &cells, &terminate).expect("draws");
    for _ in 0..5 {
        assert_eq!(flat_policy(&grid, "Same", &cells, &terminate).expect("draws"), first);
    }
}

#[test]
fn extreme_rewards_still_draw() {
    let big = 1e300;
    let cases = [
        vec![vec![big, -big, big]],
        vec![vec![big, big], vec![big / 2.0, big]],
        vec![vec![1e-300, 2e-300, 3e-300]],
        vec![vec![5e-324, 0.0]],
        vec![vec![1e15, 1e15 + 1.0]],
        vec![vec![-big; 3]],
    ];
    for seeds in cases {
        let svg = learning_curve("Extreme", &seeds, 2).unwrap_or_else(|e| panic!("{seeds:?}: {e}"));
        parse(&svg);
    }
    let error =
        learning_curve("Too big", &[vec![0.0], vec![1.0, -f64::MAX]], 2).expect_err("refused");
    assert_eq!(
        error.to_string(),
        "reward -1.7976931348623157e308 in episode 2 of seed 2 is too large to draw (beyond ±1e300)"
    );
}

#[test]
fn huge_titles_and_names_are_cut() {
    let long = "x".repeat(100_000);
    let grid = Grid {
        width: 2,
        height: 1,
        regions: vec![region(&long, &[(0, 0)])],
        walls: vec![],
        starts: vec![],
    };
    let choices = vec![((1, 0), long.clone())];
    let pictures = [
        options_policy(&grid, &long, &choices, &[]).expect("draws"),
        learning_curve(&long, &[vec![1.0]], 1).expect("draws"),
    ];
    for svg in &pictures {
        let doc = parse(svg);
        let width: f64 =
            doc.root_element().attribute("width").expect("width").parse().expect("number");
        assert!(width < 5000.0, "{width}");
        let longest = texts(&doc).iter().map(|t| t.chars().count()).max().unwrap_or(0);
        assert!(longest < 1000, "{longest}");
    }
}

#[test]
fn an_option_without_a_name_is_listed_as_such() {
    let svg =
        options_policy(&small_grid(), "Blank", &[((0, 0), String::new())], &[]).expect("draws");
    assert!(has_text(&parse(&svg), "(no name)"));
}

#[test]
fn memory_slices_are_one_map_each_with_shared_colours() {
    let grid = small_grid();
    // Two memory slices: "go B" appears only in the second, "go C" only in the first.
    let slices = vec![
        ("b = [0]".to_string(), vec![((0, 0), "go C".to_string()), ((1, 0), "go A".to_string())]),
        ("b = [1]".to_string(), vec![((0, 0), "go B".to_string()), ((1, 0), "go A".to_string())]),
    ];
    let maps = options_policy_slices(&grid, "Options", &slices, &names(&["go A"])).expect("draws");
    assert_eq!(maps.len(), 2);
    let colour_of = |svg: &str, name: &str, slice: &[((i64, i64), String)]| {
        let expected =
            options_policy(&grid, "x", slice, &names(&["go A", "go C", "go B"])).expect("draws");
        assert_eq!(rect_fills(&parse(svg)), rect_fills(&parse(&expected)), "{name}");
    };
    // Each map is the plain map drawn with the order over all slices.
    colour_of(&maps[0], "first slice", &slices[0].1);
    colour_of(&maps[1], "second slice", &slices[1].1);
    assert!(has_text(&parse(&maps[1]), "Options, b = [1]"));
    // Errors name the slice; no slice is an error.
    let bad = vec![("b = [2]".to_string(), vec![((9, 9), "go A".to_string())])];
    let err = options_policy_slices(&grid, "Options", &bad, &[]).unwrap_err();
    assert!(err.message().starts_with("memory slice \"b = [2]\": "), "{}", err.message());
    assert!(options_policy_slices(&grid, "Options", &[], &[]).is_err());
}
