//! Renders the case-study pictures (15 x 15 grid, regions A, B and C) into a folder.
//!
//! `cargo run -p hstl-pictures --example case_study -- /tmp/pictures`

use std::path::PathBuf;

use hstl_pictures::{
    Action, Cell, Grid, Panel, Region, RegionKind, RunStep, Series, flat_policy, learning_curve,
    learning_curves, options_policy, sample_run,
};

/// A small seeded generator so the example is deterministic without extra dependencies.
struct Lcg(u64);

impl Lcg {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn rect(
    name: &str,
    xs: std::ops::RangeInclusive<i64>,
    ys: std::ops::RangeInclusive<i64>,
) -> Region {
    let cells = xs.flat_map(|x| ys.clone().map(move |y| (x, y))).collect();
    Region::new(name, cells)
}

/// The greedy action towards the region, or `None` inside it.
fn towards(region: &Region, (x, y): (i64, i64)) -> Option<Action> {
    if region.cells.contains(&(x, y)) {
        return None;
    }
    let &(tx, ty) = region
        .cells
        .iter()
        .min_by_key(|(cx, cy)| (cx - x).abs() + (cy - y).abs())
        .expect("regions are not empty");
    Some(if (tx - x).abs() >= (ty - y).abs() {
        if tx > x { Action::Right } else { Action::Left }
    } else if ty > y {
        Action::Up
    } else {
        Action::Down
    })
}

/// Where `action` leads from `(x, y)` without a slip.
fn intended((x, y): (i64, i64), action: Action) -> (i64, i64) {
    let (nx, ny) = match action {
        Action::Up => (x, y + 1),
        Action::Down => (x, y - 1),
        Action::Left => (x - 1, y),
        Action::Right => (x + 1, y),
    };
    if (0..15).contains(&nx) && (0..15).contains(&ny) { (nx, ny) } else { (x, y) }
}

fn step(at: (i64, i64), action: Action, rng: &mut Lcg) -> (i64, i64) {
    let all = [Action::Up, Action::Down, Action::Left, Action::Right];
    let taken = if rng.next_f64() < 0.7 {
        action
    } else {
        let others: Vec<Action> = all.into_iter().filter(|a| *a != action).collect();
        others[((rng.next_f64() * 3.0) as usize).min(2)]
    };
    intended(at, taken)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "/tmp/pictures".into()));
    std::fs::create_dir_all(&dir)?;
    let grid = Grid {
        width: 15,
        height: 15,
        regions: vec![
            rect("A", 4..=8, 11..=13),
            rect("B", 2..=4, 2..=4),
            rect("C", 10..=12, 2..=6),
        ],
        walls: vec![],
        starts: vec![],
    };
    // An obstacle to avoid, drawn hatched red.
    let mut grid = grid;
    grid.regions.push(rect("Obstacle", 7..=8, 6..=8).with_kind(RegionKind::Avoid));
    let mut rng = Lcg(7);
    let cells: Vec<(i64, i64)> = (0..15).flat_map(|x| (0..15).map(move |y| (x, y))).collect();
    for region in &grid.regions {
        let arrows: Vec<Cell> = cells
            .iter()
            .filter_map(|&(x, y)| towards(region, (x, y)).map(|action| Cell { x, y, action }))
            .collect();
        let terminate = region.cells.clone();
        let svg = flat_policy(
            &grid,
            &format!("Flat policy: go to {}", region.name),
            &arrows,
            &terminate,
        )?;
        std::fs::write(dir.join(format!("flat_{}.svg", region.name)), svg)?;
    }
    let names: Vec<String> = ["A", "B", "C"].iter().map(|r| format!("go to {r}")).collect();
    let choices: Vec<((i64, i64), String)> = cells
        .iter()
        .filter(|&&(x, y)| (x + y) % 7 != 0)
        .map(|&(x, y)| ((x, y), names[((x / 5) + (y / 5)) as usize % 3].clone()))
        .collect();
    std::fs::write(
        dir.join("options.svg"),
        options_policy(&grid, "Options policy", &choices, &names)?,
    )?;
    let many: Vec<String> = (0..16).map(|i| format!("option {i:02}")).collect();
    let choices: Vec<((i64, i64), String)> = cells
        .iter()
        .map(|&(x, y)| ((x, y), many[((x / 4) * 4 + y / 4) as usize % 16].clone()))
        .collect();
    std::fs::write(
        dir.join("options_16.svg"),
        options_policy(&grid, "Options policy with 16 options", &choices, &many)?,
    )?;
    for run in 0..2 {
        let mut at = (6, 7);
        let mut steps = Vec::new();
        let mut target = run;
        for _ in 0..90 {
            let region = &grid.regions[target % 3];
            let option = names[target % 3].clone();
            match towards(region, at) {
                Some(action) => {
                    steps.push(RunStep { cell: at, option, intended: Some(intended(at, action)) });
                    at = step(at, action, &mut rng);
                }
                None => {
                    steps.push(RunStep { cell: at, option, intended: None });
                    target += 1;
                }
            }
        }
        steps.push(RunStep { cell: at, option: names[target % 3].clone(), intended: None });
        let title = format!("Sample run {}\nan example of 90 steps", run + 1);
        let svg = sample_run(&grid, &title, &steps, &names)?;
        std::fs::write(dir.join(format!("run_{}.svg", run + 1)), svg)?;
    }
    let seeds: Vec<Vec<f64>> = (0..5)
        .map(|_| {
            (0..600)
                .map(|e| {
                    let progress = 1.0 / (1.0 + (-(e as f64 - 200.0) / 60.0).exp());
                    -40.0 + 55.0 * progress + (rng.next_f64() - 0.5) * 30.0
                })
                .collect()
        })
        .collect();
    std::fs::write(dir.join("curve.svg"), learning_curve("Learning curve", &seeds, 20)?)?;
    let shifted: Vec<Vec<f64>> =
        seeds.iter().map(|s| s.iter().map(|v| v * 0.8 + 12.0).collect()).collect();
    let panel = Panel {
        y_label: "reward per episode".into(),
        series: vec![
            Series { label: "first.hstl".into(), seeds: seeds.clone() },
            Series { label: "second.hstl".into(), seeds: shifted },
        ],
    };
    let overlay = learning_curves("Learning curves\n5 seeds each", &[panel], 20)?;
    std::fs::write(dir.join("curves.svg"), overlay)?;
    println!("wrote pictures to {}", dir.display());
    Ok(())
}
