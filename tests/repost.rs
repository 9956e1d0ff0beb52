//! RePoSt (seed 001): the meta-module operations derived by search, each a
//! sequence of real rotations that certifies clean (lattice, exact sweeps,
//! mechanics under the default model, the structure resting on the ground).

use reconfcheck::algorithms::repost::metamodule::{Direction, Meta, State};
use reconfcheck::algorithms::repost::operations::{self, Role};
use reconfcheck::algorithms::repost::operation_schedule;
use reconfcheck::certify::{Options, World, certify};
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::process::Command;

fn model() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml")
}

fn fill_name(fill: State) -> &'static str {
    if fill == State::Full { "full" } else { "sparse" }
}

/// (direction, assemble, dismantle, transfer, assemble, support moves):
/// what the search derives today. A change in the rules, the scene or the
/// search that changes a count must be looked at (and docs/repost.md
/// updated), not just re-pinned.
const COUNTS: &[(Direction, State, usize, usize, usize, usize)] = &[];

#[test]
fn every_operation_is_derived_in_all_six_directions_with_its_move_counts() {
    let mut got = Vec::new();
    for fill in [State::Sparse, State::Full] {
        for dir in Direction::ALL {
            let p = match operations::derive(dir, fill) {
                Ok(p) => p,
                Err(e) => {
                    eprintln!("{dir:?} {fill:?}: {e}");
                    continue;
                }
            };
            got.push((
                dir,
                fill,
                p.count(Role::Dismantle),
                p.count(Role::Transfer),
                p.count(Role::Assemble),
                p.count(Role::Support),
            ));
            eprintln!(
                "{:>6} {:>6}: dismantle {:>3} transfer {:>3} assemble {:>3} support {:>3} total {:>3} strict {} {}",
                dir.name(),
                fill_name(fill),
                p.count(Role::Dismantle),
                p.count(Role::Transfer),
                p.count(Role::Assemble),
                p.count(Role::Support),
                p.rotations.len(),
                p.strict,
                p.order
            );
        }
    }
    assert_eq!(got, COUNTS);
}
