//! Load maps on the page: which steps get one, and their packed form.
//!
//! A load map is every connector of a step with its utilisation. The page
//! carries one for every step when they fit [`LOAD_MAP_BUDGET`] (the
//! default scenario: all 184), else the steps that matter first — the
//! worst, the first overloaded ones, the final configuration — and then
//! steps spread evenly over the run until the budget is spent (the
//! sandcastle: about a dozen). A connector packs into 12 bytes
//! ([`LoadMapData`]), so the budget bounds the maps at 24 MB of base64:
//! the page stays under the 50 MB it promises.

use super::replay::base64;
use crate::certify::{self, Report, ViolationKind};
use crate::error::InputError;
use crate::mechanics::analysis::Analysis;
use crate::mechanics::model::Model;
use crate::mechanics::structure::Structure;
use crate::schedule::Schedule;
use serde::Serialize;

/// Connectors all of a page's load maps may carry together.
pub const LOAD_MAP_BUDGET: usize = 1_500_000;

/// The worst and first overloaded steps, mapped whatever the budget.
const FIRST: usize = 8;

/// Contact coordinates are packed in units of 1/32 d (±1,024 d).
const POSITION_SCALE: f32 = 32.0;
/// Utilisation is packed in units of 2⁻²⁰ up to 16; more, or NaN, packs
/// as the largest value — drawn as overloaded, never as within limits.
const UTILISATION_SCALE: f64 = (1u32 << 20) as f64;
const UTILISATION_MAX: u32 = (1 << 24) - 1;

/// Why a step has a load map (the viewer lists all but `spread` in its
/// menu).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Why {
    /// The step of the highest utilisation.
    Worst,
    /// One of the first overloaded steps.
    Overloaded,
    /// The final configuration.
    Final,
    /// Every step fits the budget, or an evenly spread one.
    Spread,
}

/// The connectors of one step with their utilisation.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadMap {
    pub step: usize,
    pub why: Why,
    pub max_utilisation: f64,
    /// `[x, y, z, nx, ny, nz, utilisation]` per connector: its contact
    /// point and normal (units of d).
    pub links: Vec<[f32; 7]>,
}

/// The load map of a structure and its analysis at `step`.
pub fn load_map(step: usize, s: &Structure, a: &Analysis) -> LoadMap {
    let links = s
        .links
        .iter()
        .zip(&a.links)
        .map(|(l, r)| {
            let (c, n) = (l.contact.as_vec3(), l.normal.as_vec3());
            [c.x, c.y, c.z, n.x, n.y, n.z, r.utilisation as f32]
        })
        .collect();
    LoadMap {
        step,
        why: Why::Spread,
        max_utilisation: a.max_utilisation,
        links,
    }
}

/// The steps mapped whatever the budget: the step of the highest
/// utilisation and the first overloaded steps (at most `n`), with why.
fn priority_steps(report: &Report, n: usize) -> Vec<(usize, Why)> {
    let mut steps = Vec::new();
    let worst = report
        .per_step
        .iter()
        .filter_map(|r| r.metrics.get("max_utilisation").map(|u| (*u, r.step)))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    steps.extend(worst.map(|w| (w.1, Why::Worst)));
    for v in &report.violations {
        if steps.len() >= n {
            break;
        }
        if v.kind == ViolationKind::Overload && !steps.iter().any(|s| s.0 == v.step) {
            steps.push((v.step, Why::Overloaded));
        }
    }
    steps
}

/// `k` of the sorted `steps`, spread evenly over them.
fn spread(steps: &[usize], k: usize) -> Vec<usize> {
    if k >= steps.len() {
        return steps.to_vec();
    }
    (0..k)
        .map(|i| steps[((2 * i + 1) * steps.len()) / (2 * k)])
        .collect()
}

/// The load maps a page of `schedule`, certified in `report` under
/// `model`, carries: the priority steps and the final configuration (step
/// `steps + 1`), then further steps evenly spread while an upper estimate
/// of their connectors fits `budget` (the most connectors per body seen so
/// far, times the most modules the run has). Maps of a step whose
/// structure has no connector are left out; so are the steps a report of
/// part of the schedule (`--steps`) did not check. Two replays of the
/// schedule, each solving only its chosen steps.
pub fn load_maps(
    schedule: &Schedule,
    model: &Model,
    report: &Report,
    budget: usize,
) -> Result<Vec<LoadMap>, InputError> {
    let last = schedule.steps.len() + 1;
    let checked = |k: usize| report.in_window(k);
    let mut first = priority_steps(report, FIRST);
    if checked(last) && !first.iter().any(|s| s.0 == last) {
        first.push((last, Why::Final));
    }
    let wanted: Vec<usize> = first.iter().map(|s| s.0).collect();
    let mut maps = Vec::new();
    let mut per_body = 0.0f64;
    for (k, st, a) in certify::load_maps_at(schedule, model, &wanted)? {
        per_body = per_body.max(st.links.len() as f64 / st.bodies.len().max(1) as f64);
        let mut m = load_map(k, &st, &a);
        m.why = first.iter().find(|s| s.0 == k).map_or(Why::Spread, |s| s.1);
        maps.push(m);
    }
    let used: usize = maps.iter().map(|m| m.links.len()).sum();
    let most_modules = report.modules.max(report.final_modules).max(1);
    let per_map = (per_body * most_modules as f64).ceil().max(1.0) as usize;
    let room = budget.saturating_sub(used) / per_map;
    let rest: Vec<usize> = (1..=last)
        .filter(|&k| checked(k) && !wanted.contains(&k))
        .collect();
    let extra = spread(&rest, room);
    if !extra.is_empty() {
        let mut more: Vec<LoadMap> = certify::load_maps_at(schedule, model, &extra)?
            .into_iter()
            .map(|(k, st, a)| load_map(k, &st, &a))
            .collect();
        // The estimate bounds the connectors unless a step has more
        // modules than the start and the end: drop the largest extras
        // until the budget holds.
        let mut total = used + more.iter().map(|m| m.links.len()).sum::<usize>();
        while total > budget {
            let Some((i, _)) = more.iter().enumerate().max_by_key(|(_, m)| m.links.len()) else {
                break;
            };
            total -= more.swap_remove(i).links.len();
        }
        maps.extend(more);
    }
    maps.retain(|m| !m.links.is_empty());
    maps.sort_by_key(|m| m.step);
    Ok(maps)
}

/// A load map as the page carries it: its connectors packed three
/// little-endian `i32` words each, in base64 —
/// `x | y << 16`, `z | nx << 16 | ny << 24`, `nz | u << 8`, with the
/// contact point in 1/32 d (`i16`), the normal in 1/127 (`i8`) and the
/// utilisation in 2⁻²⁰ (24 bits, saturating: NaN and anything from 16 up
/// read as 16, overloaded).
#[derive(Serialize)]
pub struct LoadMapData {
    pub step: usize,
    pub why: Why,
    pub max_utilisation: f64,
    pub connectors: usize,
    pub links: String,
}

fn pack_position(x: f32) -> u32 {
    ((x * POSITION_SCALE).round().clamp(-32768.0, 32767.0) as i32 as u32) & 0xffff
}

fn pack_normal(x: f32) -> u32 {
    ((x * 127.0).round().clamp(-127.0, 127.0) as i32 as u32) & 0xff
}

fn pack_utilisation(u: f32) -> u32 {
    let q = f64::from(u) * UTILISATION_SCALE;
    if q.is_nan() || q >= UTILISATION_MAX as f64 {
        UTILISATION_MAX
    } else {
        q.round().max(0.0) as u32
    }
}

impl LoadMapData {
    pub fn of(m: &LoadMap) -> LoadMapData {
        let mut words = Vec::with_capacity(3 * m.links.len());
        for l in &m.links {
            words.push((pack_position(l[0]) | pack_position(l[1]) << 16) as i32);
            words.push(
                (pack_position(l[2]) | pack_normal(l[3]) << 16 | pack_normal(l[4]) << 24) as i32,
            );
            words.push((pack_normal(l[5]) | pack_utilisation(l[6]) << 8) as i32);
        }
        LoadMapData {
            step: m.step,
            why: m.why,
            max_utilisation: m.max_utilisation,
            connectors: m.links.len(),
            links: base64(&words),
        }
    }
}

/// The inverse of [`LoadMapData::of`], as the viewer decodes it.
#[cfg(test)]
pub fn unpack(words: &[i32]) -> Vec<[f32; 7]> {
    words
        .chunks(3)
        .map(|w| {
            let (a, b, c) = (w[0], w[1], w[2]);
            [
                ((a << 16) >> 16) as f32 / POSITION_SCALE,
                (a >> 16) as f32 / POSITION_SCALE,
                ((b << 16) >> 16) as f32 / POSITION_SCALE,
                ((b << 8) >> 24) as f32 / 127.0,
                (b >> 24) as f32 / 127.0,
                ((c << 24) >> 24) as f32 / 127.0,
                ((c as u32 >> 8) & 0xff_ffff) as f32 / UTILISATION_SCALE as f32,
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packing_keeps_positions_normals_and_utilisation_to_their_resolution() {
        let links = vec![
            [
                1.207_106_8,
                -0.5,
                0.5,
                0.707_106_77,
                0.0,
                -0.707_106_77,
                0.346_899_1,
            ],
            [-95.25, 47.0, -0.03125, -1.0, 1.0, 0.0, 1.000_001],
            [3.0, 2.0, 1.0, 0.0, -0.5, 0.5, 0.0],
        ];
        let m = LoadMap {
            step: 4,
            why: Why::Worst,
            max_utilisation: 1.000_001,
            links: links.clone(),
        };
        let d = LoadMapData::of(&m);
        assert_eq!(d.connectors, 3);
        let back = unpack(&super::super::replay::unbase64(&d.links));
        for (l, b) in links.iter().zip(&back) {
            for k in 0..3 {
                assert!((l[k] - b[k]).abs() <= 0.5 / POSITION_SCALE, "{l:?} {b:?}");
            }
            for k in 3..6 {
                assert!((l[k] - b[k]).abs() <= 0.5 / 127.0 + 1e-6, "{l:?} {b:?}");
            }
            assert!((l[6] - b[6]).abs() <= 1e-6, "{l:?} {b:?}");
        }
        // Just over capacity stays over capacity.
        assert!(back[1][6] > 1.0);
    }

    #[test]
    fn a_nan_or_huge_utilisation_packs_as_overloaded_never_as_within_limits() {
        for u in [f32::NAN, f32::INFINITY, 16.0, 1e30] {
            let m = LoadMap {
                step: 1,
                why: Why::Spread,
                max_utilisation: f64::NAN,
                links: vec![[0.0, 0.0, 0.0, 0.0, 0.0, 1.0, u]],
            };
            let back = unpack(&super::super::replay::unbase64(&LoadMapData::of(&m).links));
            assert!(back[0][6] >= 15.99, "{u} → {}", back[0][6]);
        }
        let m = LoadMap {
            step: 1,
            why: Why::Spread,
            max_utilisation: 0.0,
            links: vec![[0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -0.0]],
        };
        let back = unpack(&super::super::replay::unbase64(&LoadMapData::of(&m).links));
        assert_eq!(back[0][6], 0.0);
    }

    #[test]
    fn spread_steps_are_evenly_placed_and_all_when_they_fit() {
        let steps: Vec<usize> = (1..=100).collect();
        assert_eq!(spread(&steps, 4), [13, 38, 63, 88]);
        assert_eq!(spread(&steps, 100), steps);
        assert_eq!(spread(&steps, 500), steps);
        assert!(spread(&steps, 0).is_empty());
    }
}
