//! `comb-study`: seed 004's move costs (SLIDE derived by search, per atom
//! model and carried load) and the 2D combing's parallel steps and atom
//! operations against n, with log–log fits, beside a naive baseline; and
//! Theorem 1 (source to target through the common comb) at the
//! meta-module level, its combing phases atom by atom.

use reconfcheck::algorithms::atom_moves::derive_slide;
use reconfcheck::error::{Error, write_file};
use reconfcheck::geometry::atom_expand::{double_slide_library, tunnel_library};
use reconfcheck::geometry::atom_search::{Carry, Legs};
use reconfcheck::lattice::AtomRest;
use reconfcheck::study::comb as study;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Meta-module counts of the random polyominoes.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "8,16,32,64,128,256,512,1024,2048,4096"
    )]
    sizes: Vec<usize>,
    #[arg(long, default_value_t = 4)]
    seed: u64,
    /// Certify the expanded schedules up to this many meta-modules.
    #[arg(long, default_value_t = 4096)]
    certify_up_to: usize,
    /// Draw the scaling plot (log–log, fits, naive baseline) to this PNG
    /// (or SVG) file.
    #[cfg(feature = "render")]
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// Draw Theorems 1 and 2 against n (meta-module steps source to
    /// target, the combing phases' parallel steps and atom operations, 2D
    /// and 3D, log–log with fits) beside the naive baseline, to this PNG
    /// (or SVG) file.
    #[cfg(feature = "render")]
    #[arg(long, value_name = "FILE")]
    theorem_plot: Option<PathBuf>,
    /// Also write the rows as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<u8, Error> {
    println!("SLIDE derived by search (3D, 2×2×2 meta-modules); paper: O(1) steps and operations");
    println!(
        "{:<11} {:<18} {:>6} {:>6} {:>8}",
        "model", "load", "steps", "ops", "states"
    );
    for rest in [AtomRest::Contracted, AtomRest::Expanded] {
        for carry in Carry::ALL {
            match derive_slide(rest, carry) {
                Some(d) => println!(
                    "{:<11} {:<18} {:>6} {:>6} {:>8}",
                    format!("{rest:?}"),
                    carry.name(),
                    d.parallel_steps(),
                    d.atom_operations(),
                    d.found.states_explored
                ),
                None => println!("{:<11} {:<18} not found", format!("{rest:?}"), carry.name()),
            }
        }
    }
    for rest in [AtomRest::Contracted, AtomRest::Expanded] {
        let how = match rest {
            AtomRest::Contracted => "searched",
            AtomRest::Expanded => "the stored SLIDE one layer at a time",
        };
        match double_slide_library(rest) {
            Some(l) => println!(
                "SLIDE between two walls, {} ({how}; paper: O(1)): {} steps, {} ops",
                format!("{rest:?}").to_lowercase(),
                l.steps.len(),
                l.steps.iter().map(Vec::len).sum::<usize>()
            ),
            None => println!("SLIDE between two walls, {rest:?}: not found"),
        }
    }
    for legs in Legs::ALL {
        match tunnel_library(AtomRest::Contracted, legs) {
            Some(t) => println!(
                "1-TUNNEL, contracted, {} (legs of any length; paper: O(1)): {} steps, {} ops, {} states",
                legs.name(),
                t.steps.len(),
                t.atom_operations(),
                t.found.states_explored
            ),
            None => println!("1-TUNNEL, contracted, {}: not found", legs.name()),
        }
    }
    println!("k-TUNNEL for k > 1 and in the expanded model: not derived (see docs/atoms.md)");
    let mut all = Vec::new();
    for rest in [AtomRest::Contracted, AtomRest::Expanded] {
        let rows = study::run(&a.sizes, a.seed, rest, a.certify_up_to)?;
        println!(
            "\n2D COMBING, {rest:?} model (random polyominoes, seed {})",
            a.seed
        );
        println!(
            "{:>6} {:>7} {:>7} {:>8} {:>9} {:>10} {:>11} {:>8} {:>8} {:>9}",
            "metas",
            "atoms",
            "mSteps",
            "steps",
            "ops",
            "naiveStep",
            "naiveOps",
            "gen s",
            "cert s",
            "certified"
        );
        for r in &rows {
            println!(
                "{:>6} {:>7} {:>7} {:>8} {:>9} {:>10} {:>11} {:>8.3} {:>8} {:>9}",
                r.metas,
                r.atoms,
                r.meta_steps,
                r.steps,
                r.operations,
                r.baseline_steps,
                r.baseline_operations,
                r.generate_s,
                r.certify_s.map_or("-".into(), |s| format!("{s:.2}")),
                r.certified.map_or("-".into(), |c| c.to_string()),
            );
        }
        print_fits(&study::series(&rows), &format!(", {rest:?}"));
        all.push((rest, rows));
    }
    #[cfg(feature = "render")]
    if let Some(p) = &a.plot {
        reconfcheck::render::comb_figures::scaling(&all, p)?;
        println!("wrote {}", p.display());
    }
    let theorem = study::theorem(&a.sizes, a.seed, AtomRest::Contracted, a.certify_up_to)?;
    println!(
        "\nTHEOREM 1 in 2D, Contracted model (random source and target, seed {}): meta-module steps per phase\n(comb S | S to common comb | common comb to comb T, latches first | comb T to T), tunnels by turns,\nthose with every leg of one, the longest leg; the combing phases expanded into atoms (1-TUNNELs have a derived atom sequence, 2-TUNNELs not)",
        a.seed
    );
    println!(
        "{:>6} {:>7} {:>22} {:>7} {:>7} {:>6} {:>5} {:>8} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "metas",
        "atoms",
        "phase steps",
        "1-TUN",
        "2-TUN",
        "short",
        "leg",
        "combStp",
        "combOps",
        "meta ok",
        "atoms ok",
        "gen s",
        "cert s"
    );
    for r in &theorem {
        let [p0, p1, p2, p3] = r.phase_steps;
        println!(
            "{:>6} {:>7} {:>22} {:>7} {:>7} {:>6} {:>5} {:>8} {:>9} {:>8} {:>8} {:>8.3} {:>8}",
            r.metas,
            r.atoms,
            format!("{p0}|{p1}|{p2}|{p3}"),
            r.tunnels[0],
            r.tunnels[1],
            r.short_tunnels,
            r.longest_leg,
            r.comb_steps,
            r.comb_operations,
            r.meta_certified.map_or("-".into(), |c| c.to_string()),
            r.atoms_certified.map_or("-".into(), |c| c.to_string()),
            r.generate_s,
            r.certify_s.map_or("-".into(), |s| format!("{s:.2}")),
        );
    }
    print_fits(&study::theorem_series(&theorem), "");
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/cube-atom.toml");
    let three = study::theorem3(
        &a.sizes,
        a.seed,
        AtomRest::Contracted,
        a.certify_up_to,
        Some(model),
    )?;
    println!(
        "\nTHEOREM 2 in 3D, Contracted model (random polycubes, seed {}): meta-module steps per phase\n(comb S | S to common comb | common comb to comb T, latches first | comb T to T), tunnels by turns;\nthe combing phases expanded into atoms and certified atom by atom (k-TUNNELs have no derived atom sequence),\ntheir highest drive-load utilisation under models/cube-atom.toml (ASSUMED figures)",
        a.seed
    );
    println!(
        "{:>6} {:>7} {:>24} {:>6} {:>6} {:>6} {:>6} {:>8} {:>9} {:>8} {:>8} {:>7} {:>8} {:>8}",
        "metas",
        "atoms",
        "phase steps",
        "k=1",
        "k=2",
        "k=3",
        "k=4",
        "combStp",
        "combOps",
        "meta ok",
        "atoms ok",
        "util",
        "gen s",
        "cert s"
    );
    for r in &three {
        let [p0, p1, p2, p3] = r.phase_steps;
        println!(
            "{:>6} {:>7} {:>24} {:>6} {:>6} {:>6} {:>6} {:>8} {:>9} {:>8} {:>8} {:>7} {:>8.3} {:>8}",
            r.metas,
            r.atoms,
            format!("{p0}|{p1}|{p2}|{p3}"),
            r.tunnels[0],
            r.tunnels[1],
            r.tunnels[2],
            r.tunnels[3],
            r.comb_steps,
            r.comb_operations,
            r.meta_certified.map_or("-".into(), |c| c.to_string()),
            r.atoms_certified.map_or("-".into(), |c| c.to_string()),
            r.comb_utilisation.map_or("-".into(), |u| format!("{u:.3}")),
            r.generate_s,
            r.certify_s.map_or("-".into(), |s| format!("{s:.2}")),
        );
    }
    print_fits(&study::theorem3_series(&three), ", 3D");
    #[cfg(feature = "render")]
    if let Some(p) = &a.theorem_plot {
        let naive = all
            .iter()
            .find(|(rest, _)| *rest == AtomRest::Contracted)
            .map(|(_, rows)| study::series(rows)[3].1.clone())
            .unwrap_or_default();
        reconfcheck::render::comb_figures::theorems(&theorem, &three, &naive, p)?;
        println!("wrote {}", p.display());
    }
    if let Some(p) = &a.json {
        let mut v: Vec<_> = all
            .iter()
            .map(|(rest, rows)| serde_json::json!({"model": format!("{rest:?}"), "rows": rows}))
            .collect();
        v.push(serde_json::json!({"model": "Contracted", "theorem_1": theorem}));
        v.push(serde_json::json!({"model": "Contracted", "theorem_2_3d": three}));
        write_file(p, serde_json::to_string_pretty(&v).expect("serialises"))?;
    }
    Ok(0)
}

/// One line per series: its log–log fit against n (`-` when it has too
/// few positive points).
fn print_fits(series: &[(&str, Vec<(f64, f64)>)], label: &str) {
    for (name, pts) in series {
        let fit = study::loglog_fit(pts).map_or("-".to_string(), |f| {
            format!("slope {:.3}, R² {:.3}", f.slope, f.r2)
        });
        println!("{name}{label} vs n: {fit}");
    }
}
