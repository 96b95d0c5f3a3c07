//! Pictures drawn from small data: the SVG parses and shows what it must; bad input errors.

use std::collections::{BTreeSet, HashMap};

use hstl_pictures::{
    Action, Cell, Grid, Panel, Region, RegionKind, RunStep, Series, flat_policy, learning_curve,
    learning_curves, options_policy, options_policy_slices, sample_run,
};
use roxmltree::{Document, Node};

/// Fill of arrows (and all text); arrows are the 7-point polygons of this colour.
const INK: &str = "#222222";
/// Fill of termination dots.
const TERMINATE: &str = "#D62728";

fn region(name: &str, cells: &[(i64, i64)]) -> Region {
    Region::new(name, cells.to_vec())
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
    for wanted in
        ["Go to A", "A", "Base", "Legend", "region to reach", "action taken", "terminates"]
    {
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
    // Each option's colour fills exactly its cells (runs along a row share a rectangle),
    // and every option of the legend has a colour of its own.
    let frame = frame(&doc, &grid);
    let mut expected: HashMap<&str, BTreeSet<(i64, i64)>> = HashMap::new();
    for (cell, name) in &choices {
        expected.entry(name.as_str()).or_default().insert(*cell);
    }
    let filled = filled_cells(&doc, &frame);
    let mut by_colour: Vec<BTreeSet<(i64, i64)>> = filled
        .iter()
        .filter(|(fill, _)| !is_neutral(fill))
        .map(|(_, cells)| cells.clone())
        .filter(|cells| !cells.is_empty())
        .collect();
    let mut wanted: Vec<BTreeSet<(i64, i64)>> = expected.into_values().collect();
    by_colour.sort();
    wanted.sort();
    assert_eq!(by_colour, wanted);
    let distinct_option_colours = rect_fills(&doc).keys().filter(|f| !is_neutral(f)).count();
    assert_eq!(distinct_option_colours, order.len() + 1);
}

/// The grid's frame in pixels: its top-left corner and the side of a cell.
struct Frame {
    left: f64,
    top: f64,
    cell: f64,
    height: i64,
}

/// Finds the grid's border (the largest unfilled rectangle) and so its cells' geometry.
fn frame(doc: &Document<'_>, grid: &Grid) -> Frame {
    let border = elements(doc, "rect")
        .into_iter()
        .filter(|r| r.attribute("fill") == Some("none"))
        .max_by(|a, b| {
            let area = |r: &Node<'_, '_>| num(r, "width") * num(r, "height");
            area(a).total_cmp(&area(b))
        })
        .expect("the grid has a border");
    let cell = num(&border, "width") / grid.width as f64;
    assert!((num(&border, "height") - cell * grid.height as f64).abs() < 1.0, "square cells");
    Frame { left: num(&border, "x"), top: num(&border, "y"), cell, height: grid.height as i64 }
}

impl Frame {
    /// The cell under the pixel `(px, py)`.
    fn cell_at(&self, (px, py): (f64, f64)) -> (i64, i64) {
        let x = ((px - self.left) / self.cell).floor() as i64;
        let row = ((py - self.top) / self.cell).floor() as i64;
        (x, self.height - 1 - row)
    }

    /// The centre pixel of a cell.
    fn centre(&self, (x, y): (i64, i64)) -> (f64, f64) {
        (
            self.left + (x as f64 + 0.5) * self.cell,
            self.top + ((self.height - 1 - y) as f64 + 0.5) * self.cell,
        )
    }

    fn inside(&self, (px, py): (f64, f64), width: i64) -> bool {
        px > self.left
            && py > self.top
            && px < self.left + self.cell * width as f64
            && py < self.top + self.cell * self.height as f64
    }
}

fn num(node: &Node<'_, '_>, attribute: &str) -> f64 {
    node.attribute(attribute)
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{attribute} of {node:?}"))
}

/// The cells each opaque fill colour covers inside the grid (rectangles may span cells).
fn filled_cells(doc: &Document<'_>, frame: &Frame) -> HashMap<String, BTreeSet<(i64, i64)>> {
    let mut out: HashMap<String, BTreeSet<(i64, i64)>> = HashMap::new();
    for rect in elements(doc, "rect") {
        let Some(fill) = rect.attribute("fill").filter(|f| *f != "none") else { continue };
        if rect.attribute("opacity") != Some("1") {
            continue;
        }
        let (x, y) = (num(&rect, "x"), num(&rect, "y"));
        let (w, h) = (num(&rect, "width"), num(&rect, "height"));
        let cells = out.entry(fill.to_owned()).or_default();
        // Only rectangles made of whole cells of the grid.
        let whole = |v: f64| (v / frame.cell - (v / frame.cell).round()).abs() < 0.02;
        if !whole(x - frame.left) || !whole(y - frame.top) || !whole(w) || !whole(h) {
            continue;
        }
        let (nx, ny) = ((w / frame.cell).round() as i64, (h / frame.cell).round() as i64);
        for i in 0..nx {
            for j in 0..ny {
                let centre = (x + (i as f64 + 0.5) * frame.cell, y + (j as f64 + 0.5) * frame.cell);
                cells.insert(frame.cell_at(centre));
            }
        }
    }
    out
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
        let steps = vec![step((0, 0), name, None), step((1, 0), name, None)];
        let run = sample_run(&grid, "Run", &steps, &order).expect("draws");
        let map_colours: BTreeSet<String> = rect_fills(&parse(&map))
            .into_iter()
            .filter(|(f, n)| !is_neutral(f) && *n == 2)
            .map(|(f, _)| f)
            .collect();
        assert_eq!(map_colours.len(), 1, "option {index}");
        // The run's legend swatch has the map's colour.
        let run_colours: BTreeSet<String> = rect_fills(&parse(&run)).into_keys().collect();
        assert!(
            run_colours.is_superset(&map_colours),
            "option {index}: {run_colours:?} vs {map_colours:?}"
        );
    }
}

fn step(cell: (i64, i64), option: &str, intended: Option<(i64, i64)>) -> RunStep {
    RunStep { cell, option: option.to_owned(), intended }
}

/// The pieces of a run's path: opaque polylines of 2 or 3 points in a colour that is not
/// neutral, wider than a pixel, with their stroke colours.
fn path_pieces(doc: &Document<'_>) -> Vec<(Vec<(f64, f64)>, String)> {
    elements(doc, "polyline")
        .iter()
        .filter(|n| n.attribute("opacity") == Some("1"))
        .filter(|n| n.attribute("stroke-width").is_some_and(|w| w != "1"))
        .filter_map(|n| Some((points(n), n.attribute("stroke").filter(|s| !is_neutral(s))?)))
        .filter(|(p, _)| (2..=3).contains(&p.len()))
        .map(|(p, s)| (p, s.to_owned()))
        .collect()
}

/// The centres of the slip crosses: pairs of dark two-point diagonals with one midpoint.
fn crosses(doc: &Document<'_>) -> Vec<(f64, f64)> {
    let diagonals: Vec<((f64, f64), f64)> = elements(doc, "polyline")
        .iter()
        .filter(|n| n.attribute("stroke") == Some(INK))
        .map(points)
        .filter(|p| p.len() == 2)
        .filter(|p| {
            let (dx, dy) = (p[1].0 - p[0].0, p[1].1 - p[0].1);
            dx != 0.0 && (dx.abs() - dy.abs()).abs() < 0.5
        })
        .map(|p| {
            let slope = (p[1].1 - p[0].1) / (p[1].0 - p[0].0);
            (((p[0].0 + p[1].0) / 2.0, (p[0].1 + p[1].1) / 2.0), slope)
        })
        .collect();
    let mut centres: Vec<(f64, f64)> = diagonals
        .iter()
        .filter(|(_, slope)| *slope > 0.0)
        .filter(|(c, _)| diagonals.iter().any(|(d, s)| *s < 0.0 && d == c))
        .map(|(c, _)| *c)
        .collect();
    centres.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    centres.dedup();
    centres
}

/// Relative luminance of a `#RRGGBB` colour, 0 to 255.
fn luma(colour: &str) -> f64 {
    let channel = |i: usize| u8::from_str_radix(&colour[i..i + 2], 16).expect("hex") as f64;
    0.299 * channel(1) + 0.587 * channel(3) + 0.114 * channel(5)
}

#[test]
fn sample_run_draws_each_move_shaded_by_time_with_start_and_end() {
    let grid = small_grid();
    let steps = vec![
        step((0, 0), "first", None),
        step((1, 0), "first", None),
        step((1, 0), "first", None),
        step((1, 1), "second", None),
        step((2, 1), "second", None),
        step((3, 1), "first", None),
        step((3, 2), "first", None),
    ];
    let svg = sample_run(&grid, "Run 1\nseed 4, the median of 9", &steps, &[]).expect("draws");
    let doc = parse(&svg);
    for wanted in [
        "Run 1",
        "seed 4, the median of 9",
        "first",
        "second",
        "start",
        "end",
        "A",
        "Base",
        "6 moves, 0 slips",
        "light early, dark late",
        "option",
        "step",
    ] {
        assert!(has_text(&doc, wanted), "missing text {wanted:?} in {:?}", texts(&doc));
    }
    assert!(crosses(&doc).len() <= 1, "no slip but the legend's");
    // One piece per move that changes cell, from centre to centre, in time order.
    let frame = frame(&doc, &grid);
    let pieces = path_pieces(&doc);
    let moves: Vec<((i64, i64), (i64, i64))> =
        steps.windows(2).map(|w| (w[0].cell, w[1].cell)).filter(|(a, b)| a != b).collect();
    assert_eq!(pieces.len(), moves.len(), "{pieces:?}");
    for ((points, _), (from, to)) in pieces.iter().zip(&moves) {
        let (a, b) = (points[points.len() - 2], points[points.len() - 1]);
        assert_eq!((frame.cell_at(a), frame.cell_at(b)), (*from, *to));
    }
    // The two stretches of `first` get darker with time.
    let first: Vec<f64> = [0, 3, 4].iter().map(|&i| luma(&pieces[i].1)).collect();
    assert!(first.windows(2).all(|w| w[1] < w[0]), "{first:?}");
}

#[test]
fn slips_are_marked_where_the_run_left_the_chosen_move() {
    let grid = Grid { width: 5, height: 4, regions: vec![], walls: vec![(2, 2)], starts: vec![] };
    // Step 1 chose Right to (2, 1) but went up to (1, 2); step 3 chose Up into the wall
    // (staying is its intended cell) and stayed: no slip; step 4 chose Right to (2, 2)?
    // no: the wall, so it intends to stay, but slipped down to (1, 1).
    let steps = vec![
        step((0, 1), "go", Some((1, 1))),
        step((1, 1), "go", Some((2, 1))),
        step((1, 2), "go", Some((1, 3))),
        step((1, 3), "go", Some((1, 3))),
        step((1, 3), "go", Some((1, 3))),
        step((1, 2), "go", Some((2, 2))),
        step((1, 2), "go", None),
    ];
    let svg = sample_run(&grid, "Slips", &steps, &[]).expect("draws");
    let doc = parse(&svg);
    assert!(has_text(&doc, "6 moves, 3 slips"), "{:?}", texts(&doc));
    let frame = frame(&doc, &grid);
    let in_grid: Vec<(f64, f64)> =
        crosses(&doc).into_iter().filter(|&c| frame.inside(c, grid.width as i64)).collect();
    // Slipped: step 1 (intended (2, 1), went to (1, 2)), step 4 (intended to stay, went to
    // (1, 2)), step 5 (intended (2, 2), stayed).
    let slipped = [((1, 1), (2, 1)), ((1, 3), (1, 3)), ((1, 2), (2, 2))];
    assert_eq!(in_grid.len(), slipped.len(), "{in_grid:?}");
    for (from, intended) in slipped {
        let (fx, fy) = frame.centre(from);
        let (ix, iy) = frame.centre(intended);
        // The cross lies in the cell slipped in, towards the intended cell.
        let hit = in_grid.iter().any(|&(cx, cy)| {
            frame.cell_at((cx, cy)) == from
                && (cx - fx) * (ix - fx) >= 0.0
                && (cy - fy) * (iy - fy) >= 0.0
                && ((cx - fx).abs() + (cy - fy).abs() > 1.0) == (from != intended)
        });
        assert!(hit, "no cross for the slip in {from:?} towards {intended:?}: {in_grid:?}");
    }
    // The timeline marks the same three slips, below the grid.
    let below = crosses(&doc).into_iter().filter(|c| c.1 > frame.top + frame.cell * 4.0).count();
    assert_eq!(below, 3);
}

#[test]
fn repeated_passes_along_one_edge_lie_side_by_side() {
    let grid = Grid { width: 3, height: 1, regions: vec![], walls: vec![], starts: vec![] };
    let steps: Vec<RunStep> =
        [(0, 0), (1, 0), (0, 0), (1, 0), (2, 0)].iter().map(|&c| step(c, "o", None)).collect();
    let doc_text = sample_run(&grid, "Back and forth", &steps, &[]).expect("draws");
    let doc = parse(&doc_text);
    let rows: BTreeSet<i64> =
        path_pieces(&doc).iter().take(3).map(|(p, _)| p[p.len() - 1].1.round() as i64).collect();
    assert_eq!(rows.len(), 3, "three passes over one edge, three lanes");
}

#[test]
fn a_run_of_one_step_has_no_path_but_still_start_and_end() {
    let svg =
        sample_run(&small_grid(), "Still", &[step((2, 2), "wait", None)], &[]).expect("draws");
    let doc = parse(&svg);
    assert!(has_text(&doc, "0 moves, 0 slips"));
    assert!(has_text(&doc, "start") && has_text(&doc, "end"));
    assert!(path_pieces(&doc).is_empty());
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
            sample_run(&stray, "t", &[step((0, 0), "o", None)], &[]),
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
        ("empty run", sample_run(&grid, "t", &[], &[]), "a sample run needs at least one step"),
        (
            "step outside",
            sample_run(&grid, "t", &[step((0, 0), "o", None), step((0, 9), "o", None)], &[]),
            "step cell (0, 9) is outside",
        ),
        (
            "intended outside",
            sample_run(&grid, "t", &[step((0, 0), "o", Some((-1, 0)))], &[]),
            "intended cell (-1, 0) is outside",
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
    assert!(err.message().starts_with("memory slice `b = [2]`: "), "{}", err.message());
    assert!(options_policy_slices(&grid, "Options", &[], &[]).is_err());
}

/// Fill of walls.
const WALL: &str = "#4A4A4A";
/// Outline and hatching of regions to avoid.
const AVOID: &str = "#C01C28";

#[test]
fn walls_fill_exactly_the_wall_cells_and_the_legend_names_them() {
    // A ring of walls with a gap, and a wall inside.
    let mut walls: Vec<(i64, i64)> = Vec::new();
    for x in 0..6 {
        walls.extend([(x, 0), (x, 4)]);
    }
    walls.extend([(0, 1), (0, 2), (0, 3), (5, 1), (5, 3), (2, 2)]);
    let grid =
        Grid { width: 6, height: 5, regions: vec![], walls: walls.clone(), starts: vec![(1, 1)] };
    let choices: Vec<((i64, i64), String)> = (0..6)
        .flat_map(|x| (0..5).map(move |y| (x, y)))
        .filter(|c| !walls.contains(c))
        .map(|c| (c, "o".to_owned()))
        .collect();
    let svg = options_policy(&grid, "Walls", &choices, &[]).expect("draws");
    let doc = parse(&svg);
    let frame = frame(&doc, &grid);
    let filled = filled_cells(&doc, &frame);
    let expected: BTreeSet<(i64, i64)> = walls.iter().copied().collect();
    assert_eq!(filled.get(WALL), Some(&expected));
    for wanted in ["wall", "start cell"] {
        assert!(has_text(&doc, wanted), "missing {wanted:?} in {:?}", texts(&doc));
    }
    // Every free cell has a choice: walls are not cells without one.
    assert!(!has_text(&doc, "no choice"), "{:?}", texts(&doc));
    // Runs of walls along a row share a rectangle.
    assert!(count_fill(&doc, "rect", WALL) <= 10, "{}", count_fill(&doc, "rect", WALL));
}

#[test]
fn regions_to_avoid_are_hatched_red_and_told_apart_in_the_legend() {
    let grid = Grid {
        width: 8,
        height: 6,
        regions: vec![
            region("Goal", &[(6, 4), (7, 4), (6, 5), (7, 5)]),
            region("Obstacle", &[(3, 1), (3, 2), (3, 3), (4, 2)]).with_kind(RegionKind::Avoid),
            region("Zone", &[(0, 5), (1, 5)]).with_kind(RegionKind::Other),
        ],
        walls: vec![],
        starts: vec![],
    };
    let svg = flat_policy(&grid, "Kinds", &[], &[]).expect("draws");
    let doc = parse(&svg);
    for wanted in ["region to reach", "region to avoid", "other region", "Goal", "Obstacle", "Zone"]
    {
        assert!(has_text(&doc, wanted), "missing {wanted:?} in {:?}", texts(&doc));
    }
    let frame = frame(&doc, &grid);
    // The red lines inside the grid (outline and hatching) all lie on the obstacle's cells.
    let obstacle: BTreeSet<(i64, i64)> = grid.regions[1].cells.iter().copied().collect();
    let red: Vec<Vec<(f64, f64)>> = elements(&doc, "polyline")
        .iter()
        .filter(|n| n.attribute("stroke") == Some(AVOID))
        .map(points)
        .filter(|p| p.iter().all(|&q| frame.inside(q, 8) || on_border(&frame, q, 8)))
        .collect();
    assert!(red.len() > 8, "outline and hatching: {}", red.len());
    for line in &red {
        let mid = ((line[0].0 + line[1].0) / 2.0, (line[0].1 + line[1].1) / 2.0);
        let near: BTreeSet<(i64, i64)> = [(-1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (1.0, -1.0)]
            .iter()
            .map(|(dx, dy)| frame.cell_at((mid.0 + dx, mid.1 + dy)))
            .collect();
        assert!(near.iter().any(|c| obstacle.contains(c)), "{line:?} is off the obstacle");
    }
}

fn on_border(frame: &Frame, (px, py): (f64, f64), width: i64) -> bool {
    let (right, bottom) =
        (frame.left + frame.cell * width as f64, frame.top + frame.cell * frame.height as f64);
    (px - frame.left).abs() < 1.5
        || (py - frame.top).abs() < 1.5
        || (px - right).abs() < 1.5
        || (py - bottom).abs() < 1.5
}

/// Each `<text>` with its anchor point and font size.
fn placed_texts(doc: &Document<'_>) -> Vec<(String, (f64, f64), f64)> {
    elements(doc, "text")
        .iter()
        .map(|n| {
            (
                n.text().unwrap_or("").trim().to_owned(),
                (num(n, "x"), num(n, "y")),
                num(n, "font-size"),
            )
        })
        .collect()
}

#[test]
fn region_names_stay_inside_small_regions_or_go_beside_them() {
    // On a 20 x 20 grid cells are 30 pixels: "C" fits a single cell, "Charger" fits two
    // cells only small (in a box), "Obstacle" does not fit one cell at all.
    let grid = Grid {
        width: 20,
        height: 20,
        regions: vec![
            region("C", &[(5, 5)]),
            region("Charger", &[(10, 10), (11, 10)]),
            region("Obstacle", &[(15, 15)]).with_kind(RegionKind::Avoid),
        ],
        walls: vec![],
        starts: vec![],
    };
    let svg = options_policy(&grid, "Small regions", &[], &[]).expect("draws");
    let doc = parse(&svg);
    let frame = frame(&doc, &grid);
    let placed = placed_texts(&doc);
    let find = |name: &str| placed.iter().find(|(t, _, _)| t == name).cloned().expect(name);
    // Inside: the text's estimated box (0.62 em a character) is within the region's cells.
    for (name, cells) in [("C", vec![(5, 5)]), ("Charger", vec![(10, 10), (11, 10)])] {
        let (_, (x, y), size) = find(name);
        let half_w = name.chars().count() as f64 * size * 0.62 / 2.0;
        for corner in [(x - half_w, y - size / 2.0), (x + half_w, y + size / 2.0)] {
            assert!(
                cells.contains(&frame.cell_at(corner)),
                "{name} leaves its region at {corner:?}"
            );
        }
        assert!(size >= 10.0, "{name} is readable: {size}");
    }
    // Beside: the obstacle's name is next to its cell, not over it, and still readable.
    let (_, (x, y), size) = find("Obstacle");
    assert_ne!(frame.cell_at((x, y)), (15, 15));
    let (cx, cy) = frame.centre((15, 15));
    assert!((x - cx).abs() < frame.cell * 2.0 && (y - cy).abs() < frame.cell * 1.5, "{x}, {y}");
    assert!(size >= 12.0, "{size}");
}

#[test]
fn flat_policies_name_regions_in_tabs_on_their_top_edges() {
    // Arrows fill every cell, so a name inside a region would hide one.
    let grid = Grid {
        width: 10,
        height: 10,
        regions: vec![
            region("Goal", &[(6, 7), (7, 7), (8, 7), (6, 6), (7, 6), (8, 6)]),
            region("Pit", &[(2, 2)]).with_kind(RegionKind::Avoid),
        ],
        walls: vec![],
        starts: vec![],
    };
    let arrows: Vec<Cell> =
        (0..10).flat_map(|x| (0..10).map(move |y| Cell { x, y, action: Action::Up })).collect();
    let svg = flat_policy(&grid, "Tabs", &arrows, &[]).expect("draws");
    let doc = parse(&svg);
    let frame = frame(&doc, &grid);
    let placed = placed_texts(&doc);
    for (name, (x0, x1, top)) in [("Goal", (6, 8, 7)), ("Pit", (2, 2, 2))] {
        let (_, (x, y), size) = placed.iter().find(|(t, _, _)| t == name).cloned().expect(name);
        let edge = frame.top + (grid.height as i64 - 1 - top) as f64 * frame.cell;
        assert!((y - edge).abs() < 3.0, "{name} at {y}, its top edge at {edge}");
        let (left, right) = (frame.centre((x0, top)).0, frame.centre((x1, top)).0);
        assert!(x >= left - 1.0 && x <= right + 1.0, "{name} at {x}, not over {left}..{right}");
        assert!(size >= 10.0, "{size}");
    }
}

#[test]
fn large_maps_draw_with_few_elements_and_spaced_numbers() {
    let side = 256_i64;
    // A border of walls and a few wall blocks; regions of every kind.
    let mut walls = Vec::new();
    for i in 0..side {
        walls.extend([(i, 0), (i, side - 1), (0, i), (side - 1, i)]);
    }
    for x in 100..140 {
        for y in 100..110 {
            walls.push((x, y));
        }
    }
    let block = |x0: i64, y0: i64, n: i64| -> Vec<(i64, i64)> {
        (x0..x0 + n).flat_map(|x| (y0..y0 + n).map(move |y| (x, y))).collect()
    };
    let grid = Grid {
        width: side as usize,
        height: side as usize,
        regions: vec![
            region("A", &block(10, 10, 20)),
            region("Hole", &block(200, 200, 3)).with_kind(RegionKind::Avoid),
            region("Tiny", &[(50, 200)]),
        ],
        walls,
        starts: vec![],
    };
    let choices: Vec<((i64, i64), String)> = (1..side - 1)
        .flat_map(|x| (1..side - 1).map(move |y| (x, y)))
        .filter(|&(x, y)| !((100..140).contains(&x) && (100..110).contains(&y)))
        .map(|(x, y)| ((x, y), if x < 128 { "left" } else { "right" }.to_owned()))
        .collect();
    let svg = options_policy(&grid, "A large map", &choices, &[]).expect("draws");
    let doc = parse(&svg);
    let rects = elements(&doc, "rect").len();
    assert!(rects < 3 * side as usize, "{rects} rectangles");
    assert!(svg.len() < 2_000_000, "{} bytes", svg.len());
    // Column numbers are round and far enough apart not to overlap.
    let frame = frame(&doc, &grid);
    let below = frame.top + frame.cell * side as f64;
    let columns: Vec<(i64, f64)> = placed_texts(&doc)
        .into_iter()
        .filter(|(_, (_, y), _)| *y > below && *y < below + 20.0)
        .filter_map(|(t, (x, _), _)| Some((t.parse().ok()?, x)))
        .collect();
    assert!(columns.len() > 5, "{columns:?}");
    for pair in columns.windows(2) {
        assert_eq!(pair[1].0 - pair[0].0, columns[1].0 - columns[0].0, "evenly spaced");
        assert!(pair[1].1 - pair[0].1 > 30.0, "{pair:?} overlap");
    }
    assert!([10, 20, 25, 50].contains(&(columns[1].0 - columns[0].0)), "{columns:?}");
    assert!(has_text(&doc, "Tiny") && has_text(&doc, "Hole") && has_text(&doc, "A"));
}

#[test]
fn a_title_note_is_a_second_line_under_the_title() {
    let svg = flat_policy(&small_grid(), "Flat policy of A\nseed 3, the median", &[], &[])
        .expect("draws");
    let doc = parse(&svg);
    let placed = placed_texts(&doc);
    let title = placed.iter().find(|(t, _, _)| t == "Flat policy of A").expect("title");
    let note = placed.iter().find(|(t, _, _)| t == "seed 3, the median").expect("note");
    assert!(note.1.1 > title.1.1 && note.2 < title.2, "{title:?} {note:?}");
}

/// The texts left of the plotting area of a learning curve: the y axis's numbers.
fn y_tick_labels(doc: &Document<'_>) -> Vec<(String, String)> {
    elements(doc, "text")
        .iter()
        .filter(|n| n.attribute("text-anchor") == Some("end"))
        .map(|n| {
            (n.text().unwrap_or("").trim().to_owned(), n.attribute("fill").unwrap_or("").to_owned())
        })
        .filter(|(t, _)| t.parse::<f64>().is_ok())
        .collect()
}

#[test]
fn curve_ticks_are_round_without_a_needless_decimal_and_one_marks_the_plateau() {
    // Rewards rise from -1000 to a plateau at -334.
    let seeds: Vec<Vec<f64>> = (0..3)
        .map(|s| {
            (0..300)
                .map(|e| if e < 100 { -1000.0 + 6.66 * e as f64 } else { -334.0 + s as f64 })
                .collect()
        })
        .collect();
    let svg = learning_curve("Plateau", &seeds, 1).expect("draws");
    let doc = parse(&svg);
    let labels = y_tick_labels(&doc);
    assert!(labels.len() >= 4, "{labels:?}");
    for (text, _) in &labels {
        assert!(!text.ends_with(".0"), "{text} has a needless decimal");
    }
    // The plateau: the mean line's average over the last 30 episodes, -333.
    let plateau: Vec<&(String, String)> = labels.iter().filter(|(_, fill)| fill != INK).collect();
    assert_eq!(plateau.len(), 1, "{labels:?}");
    assert_eq!(plateau[0].0, "-333");
    assert!(has_text(&doc, "dashes: mean of the last 10% of episodes"));
}

#[test]
fn overlaid_curves_draw_one_mean_line_per_spec_named_in_the_legend() {
    let curve = |offset: f64| -> Vec<Vec<f64>> {
        (0..4).map(|s| (0..120).map(|e| offset + (e as f64).sqrt() + s as f64).collect()).collect()
    };
    let panels = [
        Panel {
            y_label: "reward per episode".into(),
            series: vec![
                Series { label: "surveillance_ot1.hstl".into(), seeds: curve(0.0) },
                Series { label: "surveillance_ot2.hstl".into(), seeds: curve(5.0) },
            ],
        },
        Panel {
            y_label: "kept windows per episode".into(),
            series: vec![Series { label: "surveillance_memory.hstl".into(), seeds: curve(100.0) }],
        },
    ];
    let svg =
        learning_curves("Learning curves of 3 specs\n4 seeds each", &panels, 5).expect("draws");
    let doc = parse(&svg);
    for wanted in [
        "Learning curves of 3 specs",
        "4 seeds each",
        "surveillance_ot1.hstl (4 seeds)",
        "surveillance_ot2.hstl (4 seeds)",
        "surveillance_memory.hstl (4 seeds)",
        "reward per episode",
        "kept windows per episode",
        "lines: mean, bands: lowest to highest seed",
        "moving average of 5 episodes",
    ] {
        assert!(has_text(&doc, wanted), "missing {wanted:?} in {:?}", texts(&doc));
    }
    // One long mean line per spec (120 points), each in its own colour.
    let lines: Vec<String> = elements(&doc, "polyline")
        .iter()
        .filter(|n| points(n).len() >= 100)
        .filter_map(|n| n.attribute("stroke").map(str::to_owned))
        .collect();
    assert_eq!(lines.len(), 3, "{lines:?}");
    assert_eq!(lines.iter().collect::<BTreeSet<_>>().len(), 3, "{lines:?}");
    // A band per spec.
    let bands = elements(&doc, "polygon").iter().filter(|n| points(n).len() >= 200).count();
    assert_eq!(bands, 3);
    let error = learning_curves(
        "t",
        &[Panel {
            y_label: "r".into(),
            series: vec![Series { label: "bad.hstl".into(), seeds: vec![] }],
        }],
        1,
    )
    .expect_err("refused");
    assert_eq!(error.to_string(), "`bad.hstl`: a learning curve needs at least one seed");
    assert!(learning_curves("t", &[], 1).is_err());
}
