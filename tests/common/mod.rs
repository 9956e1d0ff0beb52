//! Shared builders for the integration tests.
#![allow(dead_code)]

use reconfcheck::certify::{self, Options, Report, ViolationKind};
use reconfcheck::lattice::Ground;
use reconfcheck::lattice::{Cell, LatticeKind};
use reconfcheck::schedule::{Event, Length, ModuleSpec, Schedule, Step};

/// A fixed 3 × 3 FCC platform in layer 0 (ids `x * 3 + y`) on the ground.
pub fn fcc_platform() -> Schedule {
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    s.ground = Some(Ground { layer: 0 });
    for x in 0..3 {
        for y in 0..3 {
            s.modules.push(ModuleSpec {
                id: (x * 3 + y) as u32,
                cell: Cell::new(x, y, 0),
                fixed: true,
            });
        }
    }
    s
}

pub fn add(s: &mut Schedule, id: u32, cell: Cell) {
    s.modules.push(ModuleSpec {
        id,
        cell,
        fixed: false,
    });
}

pub fn step(s: &mut Schedule, events: Vec<Event>) {
    s.steps.push(Step { events });
}

pub fn rot(module: u32, pivot: u32, from: Cell, to: Cell) -> Event {
    Event::Rotate {
        module,
        pivot,
        from,
        to,
        route: reconfcheck::lattice::Route::Octagonal,
    }
}

/// Certifies with the lattice checks only (these tests are about them).
pub fn lattice_report(s: &Schedule) -> Report {
    let opts = Options::lattice_only();
    certify::certify(s, &opts).expect("usable input")
}

pub fn kinds(r: &Report) -> Vec<(ViolationKind, usize)> {
    r.violations.iter().map(|v| (v.kind, v.step)).collect()
}
