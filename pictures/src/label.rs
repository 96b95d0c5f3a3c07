//! Where a region's name goes: inside its largest fitting rectangle of cells, as large as
//! fits, or beside the region in a small box when no readable size fits inside.

use std::collections::HashSet;

/// A rectangle of whole cells: columns `x0..=x1`, rows `y0..=y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CellBox {
    pub(crate) x0: i64,
    pub(crate) x1: i64,
    pub(crate) y0: i64,
    pub(crate) y1: i64,
}

/// Width of a character in a bold label, as a share of the font's pixel size (generous).
const CHAR_WIDTH: f64 = 0.68;
/// The largest label, in pixels.
pub(crate) const MAX_LABEL_PX: f64 = 120.0;

impl CellBox {
    /// Columns.
    pub(crate) fn width(&self) -> i64 {
        self.x1 - self.x0 + 1
    }

    /// Rows.
    pub(crate) fn height(&self) -> i64 {
        self.y1 - self.y0 + 1
    }
}

/// The pixel size of a label of `chars` characters that fits a box of `w` x `h` pixels
/// with a margin, at most [`MAX_LABEL_PX`].
pub(crate) fn fitting_size(chars: usize, w: f64, h: f64) -> f64 {
    let chars = chars.max(1) as f64;
    (h * 0.75).min(w * 0.86 / (chars * CHAR_WIDTH)).min(MAX_LABEL_PX)
}

/// The rectangle of cells, all inside the region, where a label of `chars` characters can
/// be largest (cells of `cell` pixels), with that size; `None` for an empty region.
///
/// Every maximal rectangle is a candidate (the histogram method, row by row from the top,
/// linear in the region's bounding box); among equally large labels the larger rectangle,
/// then the first found, wins.
pub(crate) fn best_box(
    cells: &HashSet<(i64, i64)>,
    chars: usize,
    cell: f64,
) -> Option<(CellBox, f64)> {
    let &(fx, fy) = cells.iter().next()?;
    let (min_x, max_x, min_y, max_y) =
        cells.iter().fold((fx, fx, fy, fy), |(ax, bx, ay, by), &(x, y)| {
            (ax.min(x), bx.max(x), ay.min(y), by.max(y))
        });
    let width = (max_x - min_x + 1) as usize;
    // Heights of the runs of region cells ending at the current row, from the top down.
    let mut heights = vec![0_i64; width];
    let mut best: Option<(CellBox, f64, i64)> = None;
    let mut stack: Vec<(usize, i64)> = Vec::with_capacity(width + 1);
    for y in (min_y..=max_y).rev() {
        for (i, h) in heights.iter_mut().enumerate() {
            *h = if cells.contains(&(min_x + i as i64, y)) { *h + 1 } else { 0 };
        }
        // Each bar popped from the stack closes the widest rectangle of its height.
        stack.clear();
        for i in 0..=width {
            let h = heights.get(i).copied().unwrap_or(0);
            let mut left = i;
            while let Some(&(start, top)) = stack.last() {
                if top < h {
                    break;
                }
                stack.pop();
                if top > 0 {
                    let candidate = CellBox {
                        x0: min_x + start as i64,
                        x1: min_x + i as i64 - 1,
                        y0: y,
                        y1: y + top - 1,
                    };
                    let size = fitting_size(
                        chars,
                        candidate.width() as f64 * cell,
                        candidate.height() as f64 * cell,
                    );
                    let area = candidate.width() * candidate.height();
                    let better = best
                        .is_none_or(|(_, s, a)| size > s + 1e-9 || (size > s - 1e-9 && area > a));
                    if better {
                        best = Some((candidate, size, area));
                    }
                }
                left = start;
            }
            stack.push((left, h));
        }
    }
    best.map(|(b, size, _)| (b, size))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(cells: &[(i64, i64)]) -> HashSet<(i64, i64)> {
        cells.iter().copied().collect()
    }

    #[test]
    fn a_full_rectangle_is_its_own_best_box() {
        let cells: Vec<(i64, i64)> = (2..=6).flat_map(|x| (1..=3).map(move |y| (x, y))).collect();
        let (b, _) = best_box(&set(&cells), 1, 40.0).unwrap();
        assert_eq!(b, CellBox { x0: 2, x1: 6, y0: 1, y1: 3 });
    }

    #[test]
    fn an_l_shape_labels_its_largest_arm() {
        // A tall column x = 0, y = 0..=5, and a long foot y = 0, x = 0..=9: a long name fits
        // the foot best.
        let mut cells: Vec<(i64, i64)> = (0..=5).map(|y| (0, y)).collect();
        cells.extend((0..=9).map(|x| (x, 0)));
        let (b, _) = best_box(&set(&cells), 8, 20.0).unwrap();
        assert_eq!(b, CellBox { x0: 0, x1: 9, y0: 0, y1: 0 });
        // A one-letter name is larger in the column, as wide as a cell but six high.
        let (b, _) = best_box(&set(&cells), 1, 20.0).unwrap();
        assert_eq!(b, CellBox { x0: 0, x1: 0, y0: 0, y1: 5 });
    }

    #[test]
    fn every_box_lies_inside_the_region() {
        // A ring with a hole and a stray cell.
        let mut cells = Vec::new();
        for x in 0..7 {
            for y in 0..5 {
                if !(2..=4).contains(&x) || !(1..=3).contains(&y) {
                    cells.push((x, y));
                }
            }
        }
        cells.push((10, 10));
        let region = set(&cells);
        for chars in 1..6 {
            let (b, size) = best_box(&region, chars, 10.0).unwrap();
            for x in b.x0..=b.x1 {
                for y in b.y0..=b.y1 {
                    assert!(region.contains(&(x, y)), "{b:?} leaves the region at ({x}, {y})");
                }
            }
            assert!(size > 0.0);
        }
        assert!(best_box(&HashSet::new(), 3, 10.0).is_none());
    }
}
