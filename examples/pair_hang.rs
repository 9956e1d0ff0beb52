//! Certifies a configuration of no steps made of RePoSt meta-modules and
//! single catoms, some fixed, under a model: how much a meta-module, or
//! two, can hang on side connectors (docs/repost.md, "paired").
//!
//! `cargo run --release --example pair_hang -- MODEL ITEM...`, where an
//! item is `f:X,Y,Z` / `h:X,Y,Z` (a SPARSE meta-module, fixed or free) or
//! `F:x,y,z` / `H:x,y,z` (one catom in that FCC cell, fixed or free).
//! Example: `models/catom-3.6mm.toml f:0,0,0 f:1,0,0 h:0,1,0 h:1,1,0`.
use reconfcheck::algorithms::repost::metamodule::Meta;
use reconfcheck::certify::{Options, certify};
use reconfcheck::lattice::{Cell, LatticeKind};
use reconfcheck::schedule::{Length, ModuleSpec, Schedule};
use std::path::PathBuf;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: pair_hang MODEL ITEM... (see the file's doc comment)");
        std::process::exit(2);
    }
    let mut s = Schedule::new(LatticeKind::Fcc, Length::mm(3.6));
    let mut id = 1;
    for item in &args[2..] {
        let parsed = item.split_once(':').and_then(|(kind, xyz)| {
            let v: Vec<i32> = xyz
                .split(',')
                .map(|t| t.parse().ok())
                .collect::<Option<_>>()?;
            (v.len() == 3).then_some((kind, v))
        });
        let Some((kind, v)) = parsed else {
            eprintln!("error: {item}: expected f:X,Y,Z, h:X,Y,Z, F:x,y,z or H:x,y,z");
            std::process::exit(2);
        };
        let cells: Vec<Cell> = match kind {
            "f" | "h" => Meta::new(v[0], v[1], v[2]).sparse_cells().to_vec(),
            "F" | "H" => vec![Cell::new(v[0], v[1], v[2])],
            _ => {
                eprintln!("error: {item}: unknown kind {kind}");
                std::process::exit(2);
            }
        };
        for cell in cells {
            s.modules.push(ModuleSpec {
                id,
                cell,
                fixed: kind == "f" || kind == "F",
            });
            id += 1;
        }
    }
    let o = Options {
        model: Some(PathBuf::from(&args[1])),
        ..Default::default()
    };
    match certify(&s, &o) {
        Ok(r) => println!("{}", r.summary()),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    }
}
