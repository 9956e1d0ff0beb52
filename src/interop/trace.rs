//! webots-visiblesim motion traces (CSV), read as schedules of rotations.
//!
//! A row is one rotation: `t_us` (start time, µs), `blockId`, the block's
//! initial cell, and the `from`, `to` and `pivot` cells, all in VisibleSim's
//! non-skewed FCCLattice, which is this crate's frame (SPEC §1). Optional
//! `linkTo` is the mover's own connector (orientation-dependent: read but
//! not used) and `linkFace` the face type the rotation passes over,
//! 0 = hexagonal, 1 = octagonal: the route of a 60° rotation (a 90°
//! rotation is octagonal only). Columns are found by their header names.

use super::visiblesim::{GroundChoice, VsConfig, VsLattice};
use crate::error::InputError;
use crate::lattice::{Cell, FccLattice, Lattice, LatticeKind, Motion, Route};
use crate::schedule::{Event, Length, ModuleSpec, Schedule, Step};
use serde_json::json;
use std::collections::{BTreeMap, HashMap, HashSet};

/// One row of a trace.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceRow {
    /// Line in the file (the header is line 1).
    pub line: usize,
    pub t_us: u64,
    pub block: u32,
    pub init: Cell,
    pub from: Cell,
    pub to: Cell,
    pub pivot: Cell,
    pub link_to: Option<u8>,
    pub link_face: Option<u8>,
}

/// How a trace becomes a schedule.
#[derive(Clone, Debug)]
pub struct TraceOptions {
    /// Duration of one rotation (µs): moves whose intervals
    /// `[t, t + move_us)` overlap are grouped into one step.
    pub move_us: u64,
    /// One move per step, in time order.
    pub one_per_step: bool,
    pub ground: GroundChoice,
    /// Grid of the configuration file (the trace itself is always FCC).
    pub lattice: VsLattice,
    pub spacing: Length,
}

const REQUIRED: [&str; 14] = [
    "t_us", "blockId", "initX", "initY", "initZ", "fromX", "fromY", "fromZ", "toX", "toY", "toZ",
    "pivotX", "pivotY", "pivotZ",
];

fn at_line(line: usize, msg: impl std::fmt::Display) -> InputError {
    InputError::new(format!("line {line}: {msg}"))
}

/// Parses a trace's rows (no lattice checks yet: see [`trace_to_schedule`]).
pub fn read_trace(text: &str) -> Result<Vec<TraceRow>, InputError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(InputError::new("empty trace: no header line"));
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |n: &str| names.iter().position(|h| *h == n);
    let mut idx = [0usize; 14];
    for (k, n) in REQUIRED.iter().enumerate() {
        idx[k] = col(n).ok_or_else(|| {
            at_line(
                1,
                format!(
                    "the header has no '{n}' column (needs {})",
                    REQUIRED.join(",")
                ),
            )
        })?;
    }
    if let Some(unknown) = names
        .iter()
        .find(|n| !REQUIRED.contains(n) && !["linkTo", "linkFace"].contains(n))
    {
        return Err(at_line(1, format!("unknown column '{unknown}'")));
    }
    let (link_to, link_face) = (col("linkTo"), col("linkFace"));
    let mut rows = Vec::new();
    for (k, l) in lines {
        let line = k + 1;
        let f: Vec<&str> = l.split(',').map(str::trim).collect();
        if f.len() != names.len() {
            return Err(at_line(
                line,
                format!("{} fields, the header has {}", f.len(), names.len()),
            ));
        }
        let int = |j: usize| -> Result<i32, InputError> {
            f[idx[j]]
                .parse::<i32>()
                .ok()
                .filter(|v| v.unsigned_abs() <= crate::schedule::MAX_COORDINATE as u32)
                .ok_or_else(|| {
                    at_line(
                        line,
                        format!("{} '{}' is not a cell coordinate", REQUIRED[j], f[idx[j]]),
                    )
                })
        };
        let cell = |j: usize| -> Result<Cell, InputError> {
            Ok(Cell::new(int(j)?, int(j + 1)?, int(j + 2)?))
        };
        let small = |c: Option<usize>, name: &str, max: u8| -> Result<Option<u8>, InputError> {
            c.map(|c| {
                f[c].parse::<u8>()
                    .ok()
                    .filter(|v| *v <= max)
                    .ok_or_else(|| at_line(line, format!("{name} '{}' is not in 0..={max}", f[c])))
            })
            .transpose()
        };
        rows.push(TraceRow {
            line,
            t_us: f[idx[0]]
                .parse()
                .map_err(|_| at_line(line, format!("t_us '{}' is not a time in µs", f[idx[0]])))?,
            block: f[idx[1]]
                .parse()
                .map_err(|_| at_line(line, format!("blockId '{}' is not a block id", f[idx[1]])))?,
            init: cell(2)?,
            from: cell(5)?,
            to: cell(8)?,
            pivot: cell(11)?,
            link_to: small(link_to, "linkTo", 11)?,
            link_face: small(link_face, "linkFace", 1)?,
        });
    }
    Ok(rows)
}

/// The route of a row's rotation, or why it is not a rotation of the
/// lattice.
fn route_of(r: &TraceRow) -> Result<Route, InputError> {
    let fcc = FccLattice;
    let (Some(a), Some(b)) = (
        fcc.direction_to(r.pivot, r.from),
        fcc.direction_to(r.pivot, r.to),
    ) else {
        return Err(at_line(
            r.line,
            format!(
                "block {}: from {} and to {} are not both neighbours of the pivot {}: not a rotation",
                r.block, r.from, r.to, r.pivot
            ),
        ));
    };
    let dot = crate::lattice::fcc_directions()[a].dot(crate::lattice::fcc_directions()[b]);
    let route = if dot.abs() < 1e-9 {
        Route::Octagonal
    } else {
        match r.link_face {
            Some(0) => Route::Hexagonal,
            Some(_) => Route::Octagonal,
            None => {
                return Err(at_line(
                    r.line,
                    format!(
                        "block {}: a 60° rotation has two routes; the trace has no linkFace to tell which",
                        r.block
                    ),
                ));
            }
        }
    };
    let motion = Motion::Rotate {
        from: r.from,
        to: r.to,
        pivot: r.pivot,
        route,
    };
    fcc.move_requirements(&motion).map_err(|e| {
        at_line(
            r.line,
            format!("block {}: not a move of the FCC lattice: {e}", r.block),
        )
    })?;
    if r.link_face == Some(0) && dot.abs() < 1e-9 {
        return Err(at_line(
            r.line,
            format!(
                "block {}: linkFace 0 (hexagonal) on a 90° rotation, which is octagonal only",
                r.block
            ),
        ));
    }
    Ok(route)
}

/// A trace as a schedule. With a configuration, its blocks are the initial
/// configuration and every row must name one of them at its initial cell;
/// without, the movers start at their initial cells and every pivot cell
/// that no mover ever occupies holds a static module (ids after the
/// largest block id). A row that is not a rotation of the lattice, or whose
/// `from` is not where its block is, is refused naming the line.
pub fn trace_to_schedule(
    rows: &[TraceRow],
    config: Option<&VsConfig>,
    opts: &TraceOptions,
) -> Result<Schedule, InputError> {
    let mut rows: Vec<&TraceRow> = rows.iter().collect();
    rows.sort_by_key(|r| r.t_us); // stable: equal times keep file order
    let mut initial: BTreeMap<u32, Cell> = BTreeMap::new();
    let mut derived_statics = 0usize;
    match config {
        Some(c) => {
            for b in &c.blocks {
                initial.insert(b.id, opts.lattice.to_cell(b.position));
            }
            for r in &rows {
                match initial.get(&r.block) {
                    None => {
                        return Err(at_line(
                            r.line,
                            format!("block {} is not in the configuration", r.block),
                        ));
                    }
                    Some(c) if *c != r.init => {
                        return Err(at_line(
                            r.line,
                            format!(
                                "block {}'s initial cell {} is not its cell {} in the configuration",
                                r.block, r.init, c
                            ),
                        ));
                    }
                    _ => {}
                }
            }
        }
        None => {
            for r in &rows {
                if let Some(c) = initial.insert(r.block, r.init)
                    && c != r.init
                {
                    return Err(at_line(
                        r.line,
                        format!(
                            "block {}'s initial cell {} was {} before",
                            r.block, r.init, c
                        ),
                    ));
                }
            }
            let mut seen: HashSet<Cell> = initial.values().copied().collect();
            for r in &rows {
                seen.insert(r.to);
            }
            let mut next = initial.keys().max().copied().unwrap_or(0);
            let mut statics: Vec<Cell> = Vec::new();
            for r in &rows {
                if !seen.contains(&r.pivot) && !statics.contains(&r.pivot) {
                    statics.push(r.pivot);
                }
            }
            derived_statics = statics.len();
            for c in statics {
                next += 1;
                initial.insert(next, c);
            }
        }
    }
    let mut where_: HashMap<u32, Cell> = initial.iter().map(|(&k, &v)| (k, v)).collect();
    let mut who: HashMap<Cell, u32> = HashMap::new();
    for (&id, &c) in &initial {
        if let Some(other) = who.insert(c, id) {
            return Err(InputError::new(format!(
                "blocks {other} and {id} start in one cell {c}"
            )));
        }
    }
    let mut steps: Vec<Step> = Vec::new();
    let mut group_end = 0u64;
    let mut in_group: HashSet<u32> = HashSet::new();
    for r in &rows {
        let route = route_of(r)?;
        let here = where_[&r.block];
        if here != r.from {
            return Err(at_line(
                r.line,
                format!("block {} moves from {} but is at {}", r.block, r.from, here),
            ));
        }
        let Some(&pivot) = who.get(&r.pivot) else {
            return Err(at_line(
                r.line,
                format!("block {}'s pivot cell {} holds no block", r.block, r.pivot),
            ));
        };
        let new_step = steps.is_empty()
            || opts.one_per_step
            || r.t_us >= group_end
            || in_group.contains(&r.block);
        if new_step {
            steps.push(Step::default());
            in_group.clear();
            group_end = 0;
        }
        group_end = group_end.max(r.t_us.saturating_add(opts.move_us));
        in_group.insert(r.block);
        steps
            .last_mut()
            .expect("a step")
            .events
            .push(Event::Rotate {
                module: r.block,
                pivot,
                from: r.from,
                to: r.to,
                route,
            });
        who.remove(&r.from);
        if let Some(other) = who.insert(r.to, r.block) {
            // Two blocks in one cell: the certifier reports it as an
            // occupancy violation; keep the trace's story going.
            who.insert(r.to, other);
        }
        where_.insert(r.block, r.to);
    }
    let mut s = Schedule::new(LatticeKind::Fcc, opts.spacing);
    s.modules = initial
        .iter()
        .map(|(&id, &cell)| ModuleSpec {
            id,
            cell,
            fixed: false,
        })
        .collect();
    s.ground = opts.ground.resolve(s.modules.iter().map(|m| m.cell));
    s.steps = steps;
    s.meta
        .insert("imported_from".into(), json!("webots-visiblesim trace"));
    s.meta.insert(
        "trace".into(),
        json!({
            "rows": rows.len(),
            "move_us": opts.move_us,
            "grouping": if opts.one_per_step { "one move per step" } else { "overlapping intervals" },
            "static_modules_from_pivots": derived_statics,
        }),
    );
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "t_us,blockId,initX,initY,initZ,fromX,fromY,fromZ,toX,toY,toZ,pivotX,pivotY,pivotZ,linkTo,linkFace";

    fn opts() -> TraceOptions {
        TraceOptions {
            move_us: 400_000,
            one_per_step: false,
            ground: GroundChoice::Lowest,
            lattice: VsLattice::Fcc,
            spacing: Length::mm(3.6),
        }
    }

    fn import(body: &str, o: &TraceOptions) -> Result<Schedule, InputError> {
        let rows = read_trace(&format!("{HEADER}\n{body}"))?;
        trace_to_schedule(&rows, None, o)
    }

    #[test]
    fn overlapping_moves_share_a_step_and_pivots_become_static_modules() {
        // Two blocks climb onto the layer above their pivots at once.
        let s = import(
            "0,1,0,0,0,0,0,0,0,0,1,1,0,0,2,1\n100,2,0,2,0,0,2,0,0,2,1,1,2,0,2,1\n500000,1,0,0,0,0,0,1,1,0,1,1,0,0,3,1",
            &opts(),
        )
        .unwrap();
        assert_eq!(s.steps.len(), 2);
        assert_eq!(s.steps[0].events.len(), 2);
        // Blocks 1, 2 and static pivots at (1,0,0) and (1,2,0).
        assert_eq!(s.modules.len(), 4);
        assert_eq!(s.ground.map(|g| g.layer), Some(0));
        let one = import(
            "0,1,0,0,0,0,0,0,0,0,1,1,0,0,2,1\n100,2,0,2,0,0,2,0,0,2,1,1,2,0,2,1",
            &TraceOptions {
                one_per_step: true,
                ..opts()
            },
        )
        .unwrap();
        assert_eq!(one.steps.len(), 2);
    }

    #[test]
    fn link_face_gives_the_route_of_a_60_degree_rotation() {
        // (0,0,0) → (0,0,1) on pivot (1,0,0): directions (−1,0,0) and
        // (−½,+½,+1/√2)·… are 60° apart.
        let hex = import("0,1,0,0,0,0,0,0,0,0,1,1,0,0,2,0", &opts()).unwrap();
        let oct = import("0,1,0,0,0,0,0,0,0,0,1,1,0,0,2,1", &opts()).unwrap();
        let route = |s: &Schedule| match &s.steps[0].events[0] {
            Event::Rotate { route, .. } => *route,
            _ => unreachable!(),
        };
        assert_eq!(route(&hex), Route::Hexagonal);
        assert_eq!(route(&oct), Route::Octagonal);
    }

    #[test]
    fn a_row_that_is_not_a_lattice_move_is_refused_naming_its_line() {
        let e = import(
            "0,1,0,0,0,0,0,0,0,0,1,1,0,0,2,1\n500000,1,0,0,0,0,0,1,5,0,1,1,0,0,3,1",
            &opts(),
        )
        .unwrap_err();
        assert!(e.message.starts_with("line 3:"), "{}", e.message);
        let e = import("0,1,0,0,0,3,0,0,3,0,1,1,0,0,2,1", &opts()).unwrap_err();
        assert!(e.message.contains("line 2"), "{}", e.message);
        let e = read_trace(&format!("{HEADER}\n0,1,0,0,0,0,0,0,0,0,1,1,0,0,2,7")).unwrap_err();
        assert!(e.message.contains("linkFace"), "{}", e.message);
    }
}
