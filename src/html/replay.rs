//! The schedule as the page replays it: the initial cells and, per step,
//! only what changed (moves as cell offsets, entries, departures), packed
//! as little-endian `i32` arrays in base64. A 33,000-module scaffold with
//! thousands of steps stays a few megabytes, and the page steps forwards
//! and backwards by applying or undoing one step's deltas.

use crate::lattice::Cell;
use crate::lattice::config::ModuleId;
use crate::schedule::{Event, Schedule};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Largest cell offset a packed move holds per axis; longer moves (long
/// tunnels) go to the `jumps` list with both cells.
const PACK: i32 = 511;

/// The encoded replay, as serialised into the page.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Replay {
    /// Module id of each instance (initial modules first, then entering
    /// ones in order of entry).
    pub ids: Vec<ModuleId>,
    /// Instances of fixed modules (sandbox, anchored base).
    pub fixed: Vec<u32>,
    /// Initial modules' cells: `[x, y, z]` per initial instance.
    pub initial: String,
    pub steps: usize,
    /// Per step: `[instance, packed offset]`, the offset
    /// `(dx+512) | (dy+512) << 10 | (dz+512) << 20`.
    pub moves: String,
    /// Per step: `[instance, fx, fy, fz, tx, ty, tz]`, moves too long to pack.
    pub jumps: String,
    /// Per step: `[instance, x, y, z]` of each module entering.
    pub enters: String,
    /// Per step: `[instance]` of each module leaving.
    pub leaves: String,
    /// Start of each step's records in each list (`steps + 1` offsets,
    /// counted in records).
    pub move_start: String,
    pub jump_start: String,
    pub enter_start: String,
    pub leave_start: String,
}

/// Encodes `s` for the page.
pub fn encode(s: &Schedule) -> Replay {
    let mut index: HashMap<ModuleId, u32> = HashMap::new();
    let mut ids = Vec::new();
    let mut initial = Vec::new();
    let mut fixed = Vec::new();
    for m in &s.modules {
        let i = ids.len() as u32;
        index.insert(m.id, i);
        ids.push(m.id);
        initial.extend([m.cell.x, m.cell.y, m.cell.z]);
        if m.fixed {
            fixed.push(i);
        }
    }
    let (mut moves, mut jumps, mut enters, mut leaves) = (vec![], vec![], vec![], vec![]);
    let mut starts: [Vec<i32>; 4] = Default::default();
    let mut instance = |id: ModuleId, ids: &mut Vec<ModuleId>| -> i32 {
        *index.entry(id).or_insert_with(|| {
            ids.push(id);
            (ids.len() - 1) as u32
        }) as i32
    };
    for step in &s.steps {
        starts[0].push((moves.len() / 2) as i32);
        starts[1].push((jumps.len() / 7) as i32);
        starts[2].push((enters.len() / 4) as i32);
        starts[3].push(leaves.len() as i32);
        for e in &step.events {
            let motion = match e {
                Event::Rotate { from, to, .. } | Event::Slide { from, to, .. } => {
                    Some((*from, *to))
                }
                Event::Tunnel { path, .. } => path.first().zip(path.last()).map(|(a, b)| (*a, *b)),
                // A docking is drawn as its arrival in the cell.
                Event::Enter { module, cell } | Event::Dock { module, cell, .. } => {
                    let i = instance(*module, &mut ids);
                    enters.extend([i, cell.x, cell.y, cell.z]);
                    None
                }
                Event::Leave { module } => {
                    leaves.push(instance(*module, &mut ids));
                    None
                }
                // Face states of cube atoms move no cell: the replay shows
                // the atoms' cells, not their arms.
                Event::Attach { .. }
                | Event::Detach { .. }
                | Event::Expand { .. }
                | Event::Contract { .. } => None,
            };
            if let Some((from, to)) = motion {
                let i = instance(e.module(), &mut ids);
                let d = [to.x - from.x, to.y - from.y, to.z - from.z];
                if d.iter().all(|c| c.abs() <= PACK) {
                    moves.extend([i, (d[0] + 512) | (d[1] + 512) << 10 | (d[2] + 512) << 20]);
                } else {
                    jumps.extend([i, from.x, from.y, from.z, to.x, to.y, to.z]);
                }
            }
        }
    }
    starts[0].push((moves.len() / 2) as i32);
    starts[1].push((jumps.len() / 7) as i32);
    starts[2].push((enters.len() / 4) as i32);
    starts[3].push(leaves.len() as i32);
    let [ms, js, es, ls] = starts.map(|v| base64(&v));
    Replay {
        ids,
        fixed,
        initial: base64(&initial),
        steps: s.steps.len(),
        moves: base64(&moves),
        jumps: base64(&jumps),
        enters: base64(&enters),
        leaves: base64(&leaves),
        move_start: ms,
        jump_start: js,
        enter_start: es,
        leave_start: ls,
    }
}

impl Replay {
    /// The cells of every module present after `step` steps (0: the initial
    /// configuration), decoded the way the page decodes them: what the
    /// tests compare with the schedule's own replay.
    pub fn cells_after(&self, step: usize) -> HashMap<ModuleId, Cell> {
        let ints = unbase64;
        let (initial, moves, jumps, enters, leaves) = (
            ints(&self.initial),
            ints(&self.moves),
            ints(&self.jumps),
            ints(&self.enters),
            ints(&self.leaves),
        );
        let (ms, js, es, ls) = (
            ints(&self.move_start),
            ints(&self.jump_start),
            ints(&self.enter_start),
            ints(&self.leave_start),
        );
        let mut cells: HashMap<ModuleId, Cell> = initial
            .chunks(3)
            .enumerate()
            .map(|(i, c)| (self.ids[i], Cell::new(c[0], c[1], c[2])))
            .collect();
        let at = |v: &[i32], k: usize| v[k] as usize;
        for k in 0..step.min(self.steps) {
            for r in moves[2 * at(&ms, k)..2 * at(&ms, k + 1)].chunks(2) {
                let id = self.ids[r[0] as usize];
                let p = r[1];
                let d = [
                    (p & 1023) - 512,
                    ((p >> 10) & 1023) - 512,
                    ((p >> 20) & 1023) - 512,
                ];
                let c = cells.get_mut(&id).expect("a moving module is present");
                *c = Cell::new(c.x + d[0], c.y + d[1], c.z + d[2]);
            }
            for r in jumps[7 * at(&js, k)..7 * at(&js, k + 1)].chunks(7) {
                cells.insert(self.ids[r[0] as usize], Cell::new(r[4], r[5], r[6]));
            }
            for r in enters[4 * at(&es, k)..4 * at(&es, k + 1)].chunks(4) {
                cells.insert(self.ids[r[0] as usize], Cell::new(r[1], r[2], r[3]));
            }
            for &i in &leaves[at(&ls, k)..at(&ls, k + 1)] {
                cells.remove(&self.ids[i as usize]);
            }
        }
        cells
    }
}

const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 of the little-endian bytes of `v` (what `atob` and an
/// `Int32Array` read back).
pub fn base64(v: &[i32]) -> String {
    let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The inverse of [`base64`].
pub fn unbase64(s: &str) -> Vec<i32> {
    let mut bytes = Vec::with_capacity(s.len() / 4 * 3);
    for chunk in s.as_bytes().chunks(4) {
        let mut n = 0u32;
        let mut valid = 0;
        for (k, &c) in chunk.iter().enumerate() {
            let v = match ALPHABET.iter().position(|&a| a == c) {
                Some(v) => {
                    valid += 1;
                    v as u32
                }
                None => 0,
            };
            n |= v << (18 - 6 * k);
        }
        let got = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        bytes.extend_from_slice(&got[..valid - 1]);
    }
    bytes
        .chunks_exact(4)
        .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_every_length_and_sign() {
        for n in 0..7 {
            let v: Vec<i32> = (0..n).map(|k| k * -123_457 + 7).collect();
            assert_eq!(unbase64(&base64(&v)), v);
        }
        // What a browser's atob reads: the standard alphabet with padding.
        assert_eq!(base64(&[1]), "AQAAAA==");
    }
}
