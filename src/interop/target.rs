//! The cells of a configuration's VisibleSim CSG target (the dialect is
//! read by [`crate::algorithms::scaffold::vs_csg`], beside the scaffold's
//! own CSG model, so that scaffold scenarios can name a VisibleSim file).

use super::visiblesim::{VsConfig, VsLattice};
use crate::algorithms::scaffold::vs_csg::parse_vs_csg;
use crate::error::InputError;
use crate::lattice::Cell;
use glam::DVec3;

/// The cells of a configuration's CSG target, as VisibleSim's `TargetCSG`
/// decides them (in this crate's frame), or `None` without a CSG target.
pub fn target_cells(cfg: &VsConfig, lattice: VsLattice) -> Result<Option<Vec<Cell>>, InputError> {
    let Some((attrs, line)) = &cfg.csg else {
        return Ok(None);
    };
    let line = *line as usize;
    let content = attrs.get("content").ok_or_else(|| {
        InputError::new(format!("line {line}, element <csg>: no content attribute"))
    })?;
    let root = parse_vs_csg(content, line)?;
    let flag = |k: &str, default: bool| -> Result<bool, InputError> {
        match attrs.get(k).map(String::as_str) {
            None => Ok(default),
            Some("true" | "1") => Ok(true),
            Some("false" | "0") => Ok(false),
            Some(o) => Err(InputError::new(format!(
                "line {line}, element <csg>: {k}=\"{o}\" is not true or false"
            ))),
        }
    };
    let translate = match attrs.get("translate") {
        None => DVec3::ZERO,
        Some(s) => {
            let v: Vec<f64> = s
                .split(',')
                .map(|t| t.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .ok()
                .filter(|v: &Vec<f64>| v.len() == 3 && v.iter().all(|x| x.is_finite()))
                .ok_or_else(|| {
                    InputError::new(format!(
                        "line {line}, element <csg>: translate '{s}' is not three numbers"
                    ))
                })?;
            DVec3::new(v[0], v[1], v[2])
        }
    };
    let mut p0 = if flag("boundingBox", true)? {
        root.bounding_box().0
    } else {
        DVec3::ZERO
    };
    if flag("offset", false)? {
        p0 -= DVec3::ONE;
    }
    let g = cfg.grid_size;
    let mut cells = Vec::new();
    // The grid is the same straight box in our frame for both lattices
    // (see `VsLattice::in_grid`): scan our cells, ask in VisibleSim's grid.
    for z in 0..g[2] {
        for y in 0..g[1] {
            for x in 0..g[0] {
                let cell = Cell::new(x, y, z);
                let p = lattice.to_grid(cell);
                let w = lattice.unscaled_world(p) + p0 - translate;
                if root.contains(w) {
                    cells.push(cell);
                }
            }
        }
    }
    Ok(Some(cells))
}
