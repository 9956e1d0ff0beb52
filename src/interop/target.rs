//! The cells of a configuration's VisibleSim CSG target (the dialect is
//! read by [`crate::algorithms::scaffold::vs_csg`], beside the scaffold's
//! own CSG model, so that scaffold scenarios can name a VisibleSim file).

use super::visiblesim::{VsConfig, VsLattice};
use crate::algorithms::scaffold::vs_csg::{parse_vs_csg, target_shift};
use crate::error::InputError;
use crate::lattice::Cell;

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
    let shift = target_shift(&root, |k| attrs.get(k).map(String::as_str), line)?;
    let g = cfg.grid_size;
    let mut cells = Vec::new();
    // The grid is the same straight box in our frame for both lattices
    // (see `VsLattice::in_grid`): scan our cells, ask in VisibleSim's grid.
    for z in 0..g[2] {
        for y in 0..g[1] {
            for x in 0..g[0] {
                let cell = Cell::new(x, y, z);
                let p = lattice.to_grid(cell);
                let w = lattice.unscaled_world(p) + shift;
                if root.contains(w) {
                    cells.push(cell);
                }
            }
        }
    }
    Ok(Some(cells))
}
