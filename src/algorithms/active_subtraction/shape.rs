//! Desired configurations of active subtraction: which cells of the initial
//! `width × height` rectangle keep their module (the *included* modules of
//! seed 003 §II), read from ASCII grids in `models/shapes2d/` and validated.
//!
//! Paper coordinates are used throughout: cell `(x, y)` with
//! `1 ≤ x ≤ width`, `1 ≤ y ≤ height`; the ground lies below `y = 1`; the
//! sink is `(0, 1)`.
//!
//! Grid file format: one text row per lattice row, the **top row first**;
//! `#` (or `X`) is an included module, `.` an excluded one. Lines starting
//! with `;` are comments; blank lines are ignored. All rows have the same
//! length; the grid's bottom-left character is cell `(1, 1)`.

use crate::error::InputError;
use crate::lattice::Cell;
use std::path::Path;

/// A desired configuration inside its initial rectangle.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shape {
    pub width: i32,
    pub height: i32,
    /// Row-major from `(1, 1)`: `included[(y − 1)·width + (x − 1)]`.
    included: Vec<bool>,
}

impl Shape {
    /// A shape from an inclusion predicate over the rectangle (not validated).
    pub fn from_fn(width: i32, height: i32, f: impl Fn(Cell) -> bool) -> Shape {
        let mut included = Vec::with_capacity((width * height).max(0) as usize);
        for y in 1..=height {
            for x in 1..=width {
                included.push(f(Cell::xy(x, y)));
            }
        }
        Shape {
            width,
            height,
            included,
        }
    }

    /// Parses an ASCII grid (see the module documentation). `origin` names
    /// the file in errors.
    pub fn parse(text: &str, origin: &Path) -> Result<Shape, InputError> {
        let err = |msg: String| InputError::new(msg).in_file(origin);
        let rows: Vec<(usize, &str)> = text
            .lines()
            .enumerate()
            .map(|(k, l)| (k + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with(';'))
            .collect();
        if rows.is_empty() {
            return Err(err("the shape grid has no rows".into()));
        }
        let width = rows[0].1.chars().count();
        let height = rows.len();
        let mut included = vec![false; width * height];
        for (row, &(line_no, line)) in rows.iter().enumerate() {
            if line.chars().count() != width {
                return Err(err(format!(
                    "line {line_no}: row has {} cells, the first row has {width}",
                    line.chars().count()
                )));
            }
            let y = height - row; // top row first
            for (k, ch) in line.chars().enumerate() {
                let inc = match ch {
                    '#' | 'X' | 'x' => true,
                    '.' => false,
                    other => {
                        return Err(err(format!(
                            "line {line_no}: unexpected character '{other}' (use '#' for included, '.' for excluded)"
                        )));
                    }
                };
                included[(y - 1) * width + k] = inc;
            }
        }
        Ok(Shape {
            width: width as i32,
            height: height as i32,
            included,
        })
    }

    /// Reads, parses and validates a shape file.
    pub fn load(path: &Path) -> Result<Shape, InputError> {
        let text = crate::error::read_file(path, "shape")?;
        let s = Shape::parse(&text, path)?;
        s.validate().map_err(|e| e.in_file(path))?;
        Ok(s)
    }

    /// Places the shape at the bottom-left of a larger initial rectangle.
    pub fn within(&self, width: i32, height: i32) -> Result<Shape, InputError> {
        check_rectangle(width, height)?;
        if self.width > width || self.height > height {
            return Err(InputError::new(format!(
                "the desired configuration ({} × {}) is not inside the initial rectangle ({width} × {height})",
                self.width, self.height
            )));
        }
        Ok(Shape::from_fn(width, height, |c| self.contains(c)))
    }

    pub fn in_rectangle(&self, c: Cell) -> bool {
        c.x >= 1 && c.y >= 1 && c.x <= self.width && c.y <= self.height
    }

    /// Whether cell `c` holds an included module.
    pub fn contains(&self, c: Cell) -> bool {
        self.in_rectangle(c) && self.included[self.index(c)]
    }

    fn index(&self, c: Cell) -> usize {
        ((c.y - 1) * self.width + (c.x - 1)) as usize
    }

    /// All cells of the initial rectangle, row-major from `(1, 1)`; the
    /// position of a cell in this list is its module id in schedules.
    pub fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        (1..=self.height).flat_map(move |y| (1..=self.width).map(move |x| Cell::xy(x, y)))
    }

    pub fn module_id(&self, c: Cell) -> u32 {
        self.index(c) as u32
    }

    pub fn included_count(&self) -> usize {
        self.included.iter().filter(|&&b| b).count()
    }

    pub fn excluded_count(&self) -> usize {
        self.included.len() - self.included_count()
    }

    /// Density ρ of seed 003 §V-B: the fraction of included modules.
    pub fn density(&self) -> f64 {
        self.included_count() as f64 / self.included.len() as f64
    }

    /// Seed 003 §II: the desired configuration must be feasible (connected,
    /// with the ground) and non-hollow (every excluded cell can reach the
    /// free space around the rectangle without crossing an included module
    /// or the ground: 4-connectivity, since a module cannot squeeze between
    /// two modules that touch at a corner).
    pub fn validate(&self) -> Result<(), InputError> {
        if self.width < 1 || self.height < 1 {
            return Err(InputError::new("the initial rectangle is empty"));
        }
        if self.included_count() == 0 {
            return Err(InputError::new(
                "the desired configuration has no included module",
            ));
        }
        let loose = self.disconnected();
        if let Some(c) = loose.first() {
            return Err(InputError::new(format!(
                "the desired configuration is disconnected: {} included module(s) are not connected to the ground, e.g. at {}",
                loose.len(),
                xy(*c)
            )));
        }
        let enclosed = self.enclosed();
        if let Some(c) = enclosed.first() {
            return Err(InputError::new(format!(
                "the desired configuration is hollow: {} excluded cell(s) are enclosed by included modules and the ground, e.g. at {}",
                enclosed.len(),
                xy(*c)
            )));
        }
        Ok(())
    }

    /// Included cells not connected to the ground through included cells.
    pub fn disconnected(&self) -> Vec<Cell> {
        let mut seen = vec![false; self.included.len()];
        let mut stack: Vec<Cell> = (1..=self.width)
            .map(|x| Cell::xy(x, 1))
            .filter(|&c| self.contains(c))
            .collect();
        for &c in &stack {
            seen[self.index(c)] = true;
        }
        while let Some(c) = stack.pop() {
            for n in neighbours4(c) {
                if self.contains(n) && !seen[self.index(n)] {
                    seen[self.index(n)] = true;
                    stack.push(n);
                }
            }
        }
        self.cells()
            .filter(|&c| self.contains(c) && !seen[self.index(c)])
            .collect()
    }

    /// Excluded cells that cannot reach the outside of the rectangle.
    pub fn enclosed(&self) -> Vec<Cell> {
        let mut seen = vec![false; self.included.len()];
        let mut stack: Vec<Cell> = self
            .cells()
            .filter(|&c| {
                !self.contains(c)
                    && neighbours4(c)
                        .iter()
                        .any(|&n| n.y >= 1 && !self.in_rectangle(n))
            })
            .collect();
        for &c in &stack {
            seen[self.index(c)] = true;
        }
        while let Some(c) = stack.pop() {
            for n in neighbours4(c) {
                if self.in_rectangle(n) && !self.contains(n) && !seen[self.index(n)] {
                    seen[self.index(n)] = true;
                    stack.push(n);
                }
            }
        }
        self.cells()
            .filter(|&c| !self.contains(c) && !seen[self.index(c)])
            .collect()
    }

    /// The grid in the file format (top row first).
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        for y in (1..=self.height).rev() {
            for x in 1..=self.width {
                s.push(if self.contains(Cell::xy(x, y)) {
                    '#'
                } else {
                    '.'
                });
            }
            s.push('\n');
        }
        s
    }
}

/// Most modules an initial rectangle may hold (2048 × 2048): SAS takes
/// time quadratic in the module count (seed 003 §IV).
pub const MAX_MODULES: i64 = 1 << 22;

/// Refuses an initial rectangle that is empty or larger than
/// [`MAX_MODULES`].
pub fn check_rectangle(width: i32, height: i32) -> Result<(), InputError> {
    if width < 1 || height < 1 {
        return Err(InputError::new(format!(
            "an initial rectangle of {width} × {height} is empty"
        )));
    }
    if width as i64 * height as i64 > MAX_MODULES {
        return Err(InputError::new(format!(
            "an initial rectangle of {width} × {height} modules is larger than this build's \
             limit of {MAX_MODULES} modules"
        )));
    }
    Ok(())
}

/// A cell of the plane as the paper writes it, `(x, y)`.
pub(crate) fn xy(c: Cell) -> String {
    format!("({}, {})", c.x, c.y)
}

pub(crate) fn neighbours4(c: Cell) -> [Cell; 4] {
    [
        Cell::xy(c.x + 1, c.y),
        Cell::xy(c.x, c.y + 1),
        Cell::xy(c.x - 1, c.y),
        Cell::xy(c.x, c.y - 1),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(t: &str) -> Result<Shape, InputError> {
        let s = Shape::parse(t, Path::new("t.txt"))?;
        s.validate()?;
        Ok(s)
    }

    #[test]
    fn the_top_row_of_the_file_is_the_highest_layer() {
        let s = parse("; U\n#..#\n#..#\n#..#\n####\n").unwrap();
        assert_eq!((s.width, s.height), (4, 4));
        assert!(s.contains(Cell::xy(1, 4)) && !s.contains(Cell::xy(2, 4)));
        assert!((1..=4).all(|x| s.contains(Cell::xy(x, 1))));
        assert_eq!(s.excluded_count(), 6);
        assert_eq!(Shape::parse(&s.to_text(), Path::new("t")).unwrap(), s);
    }

    #[test]
    fn hollow_shapes_are_rejected() {
        let e = parse("###\n#.#\n###\n").unwrap_err();
        assert!(
            e.message.contains("hollow") && e.message.contains("(2, 2)"),
            "{e}"
        );
        // A pocket closed by the ground is hollow too.
        let e = parse("###\n#.#\n").unwrap_err();
        assert!(e.message.contains("hollow"), "{e}");
        // Touching at a corner closes a pocket: modules cannot pass diagonally.
        let e = parse(".#.\n#.#\n.#.\n").unwrap_err();
        assert!(
            e.message.contains("hollow") || e.message.contains("disconnected"),
            "{e}"
        );
    }

    #[test]
    fn disconnected_and_floating_shapes_are_rejected() {
        let e = parse("#..\n...\n..#\n").unwrap_err();
        assert!(
            e.message.contains("disconnected") && e.message.contains("(1, 3)"),
            "{e}"
        );
        let e = parse("...\n...\n").unwrap_err();
        assert!(e.message.contains("no included module"), "{e}");
    }

    #[test]
    fn malformed_grids_name_the_file_and_line() {
        let e = Shape::parse("##\n#\n", Path::new("bad.txt")).unwrap_err();
        assert!(
            e.to_string().contains("bad.txt") && e.message.contains("line 2"),
            "{e}"
        );
        let e = Shape::parse("#?\n", Path::new("bad.txt")).unwrap_err();
        assert!(e.message.contains("'?'"), "{e}");
    }

    #[test]
    fn a_shape_larger_than_the_initial_rectangle_is_rejected() {
        let s = parse("##\n##\n").unwrap();
        assert!(s.within(1, 5).unwrap_err().message.contains("not inside"));
        let big = s.within(4, 3).unwrap();
        assert_eq!(big.included_count(), 4);
        assert!(big.contains(Cell::xy(2, 2)) && !big.contains(Cell::xy(3, 1)));
        // Rectangles beyond the module limit are refused, not allocated.
        assert!(
            s.within(100_000, 100_000)
                .unwrap_err()
                .message
                .contains("limit of 4194304")
        );
        assert!(s.within(i32::MAX, i32::MAX).is_err());
    }
}
