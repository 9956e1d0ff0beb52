//! Meta-module shape files: one meta-module per line, written as its
//! leader's FCC cell `x y z`, optionally followed by `sparse` or `full`
//! (default sparse); `#` starts a comment. A cell that is not a leader
//! cell `(4X, 3Y − (Z mod 2), 4Z)` is refused, naming the file, the line
//! and the cell.

use super::metamodule::{Meta, State};
use crate::error::InputError;
use crate::lattice::Cell;
use std::collections::BTreeMap;
use std::path::Path;

/// The meta-module whose leader is `c`, if `c` is a leader cell.
pub fn meta_of_leader(c: Cell) -> Option<Meta> {
    if c.z.rem_euclid(4) != 0 || c.x.rem_euclid(4) != 0 {
        return None;
    }
    let z = c.z.div_euclid(4);
    let y = c.y + z.rem_euclid(2);
    if y.rem_euclid(3) != 0 {
        return None;
    }
    let m = Meta::new(c.x.div_euclid(4), y.div_euclid(3), z);
    (m.leader() == c).then_some(m)
}

/// Parses a shape file's text; `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> Result<BTreeMap<Meta, State>, InputError> {
    let mut out = BTreeMap::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let err = |m: String| InputError::new(format!("line {}: {m}", k + 1)).in_file(path);
        let words: Vec<&str> = line.split_whitespace().collect();
        if !(3..=4).contains(&words.len()) {
            return Err(err(format!("expected 'x y z [sparse|full]', got '{line}'")));
        }
        let mut v = [0i32; 3];
        for (i, w) in words[..3].iter().enumerate() {
            v[i] = w
                .parse()
                .map_err(|_| err(format!("'{w}' is not an integer")))?;
            if v[i].unsigned_abs() > 1 << 20 {
                return Err(err(format!("coordinate {w} is out of range")));
            }
        }
        let c = Cell::new(v[0], v[1], v[2]);
        let state = match words.get(3).copied() {
            None | Some("sparse") => State::Sparse,
            Some("full") => State::Full,
            Some(w) => return Err(err(format!("unknown state '{w}' (sparse or full)"))),
        };
        let m = meta_of_leader(c).ok_or_else(|| {
            err(format!(
                "cell {c} is not on the meta-module lattice (leaders sit at (4X, 3Y − (Z mod 2), 4Z))"
            ))
        })?;
        if out.insert(m, state).is_some() {
            return Err(err(format!("meta-module at cell {c} is listed twice")));
        }
    }
    if out.is_empty() {
        return Err(InputError::new("no meta-module in the shape").in_file(path));
    }
    Ok(out)
}

/// Reads a shape file.
pub fn load(path: &Path) -> Result<BTreeMap<Meta, State>, InputError> {
    let text = crate::error::read_file(path, "meta-module shape")?;
    parse(&text, path)
}

/// Writes a shape as text (leaders, one a line).
pub fn to_text(shape: &BTreeMap<Meta, State>) -> String {
    let mut s = String::new();
    for (m, st) in shape {
        let l = m.leader();
        s.push_str(&format!("{} {} {}", l.x, l.y, l.z));
        if *st == State::Full {
            s.push_str(" full");
        }
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaders_round_trip_and_other_cells_are_refused() {
        for m in [
            Meta::new(0, 0, 0),
            Meta::new(-2, 3, 1),
            Meta::new(1, -1, -1),
        ] {
            assert_eq!(meta_of_leader(m.leader()), Some(m));
        }
        assert_eq!(meta_of_leader(Cell::new(1, 0, 0)), None);
        assert_eq!(meta_of_leader(Cell::new(0, 0, 4)), None); // Z odd: y = −1
        let e = parse("0 0 0\n4 1 0\n", Path::new("s.txt"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("s.txt") && e.contains("line 2") && e.contains("(4, 1, 0)"),
            "{e}"
        );
    }
}
