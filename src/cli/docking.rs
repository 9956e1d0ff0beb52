//! `docking-study`: seed 002's Figs. 10, 11 and the naive orders of Fig. 3.

use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::study::docking as study;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Directory of the shapes' CSG files.
    #[arg(long, default_value = "models/docking")]
    models: PathBuf,
    /// Runs (RNG seeds 0, 1, …) per shape and scale.
    #[arg(long, default_value_t = 10)]
    seeds: u64,
    /// Scale factor (1, 2 or 4 × the base scale) of Fig. 11 and the naive orders.
    #[arg(long, default_value_t = 2.0)]
    factor: f64,
    /// Also write the tables' data as JSON.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Also draw Figs. 10 and 11 as `fig10.png` and `fig11.png` in this
    /// existing folder (overwriting them).
    #[cfg(feature = "render")]
    #[arg(long, value_name = "DIR")]
    plot_dir: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<u8, Error> {
    if a.seeds == 0 || !(a.factor.is_finite() && a.factor > 0.0) {
        return Err(
            InputError::new("docking-study needs --seeds ≥ 1 and a positive --factor").into(),
        );
    }
    #[cfg(feature = "render")]
    if let Some(d) = &a.plot_dir {
        check_plot_dir(d)?;
    }
    let messages = study::messages(&a.models, a.seeds)?;
    let curves = study::availability(&a.models, a.factor, a.seeds)?;
    let naive = study::naive_orders(&a.models, a.factor, 0)?;
    print!("{}", study::tables(&messages, &curves, &naive));
    if let Some(p) = a.json {
        let v = serde_json::json!({
            "fig10": messages,
            "fig10_fits": study::message_fits(&messages)
                .into_iter()
                .map(|(shape, fit)| serde_json::json!({"shape": shape, "fit": fit}))
                .collect::<Vec<_>>(),
            "fig11": curves,
            "naive": naive,
        });
        write_file(&p, serde_json::to_string_pretty(&v).expect("serialises"))?;
    }
    #[cfg(feature = "render")]
    if let Some(d) = &a.plot_dir {
        use reconfcheck::render::docking_figures as figs;
        let (f10, f11) = (d.join("fig10.png"), d.join("fig11.png"));
        figs::fig10(&messages, a.seeds, &f10)?;
        figs::fig11(&curves, a.factor, a.seeds, &f11)?;
        eprintln!("wrote {} and {}", f10.display(), f11.display());
    }
    Ok(0)
}

/// Refuses a `--plot-dir` that is not an existing folder before the study
/// runs (exit 2, naming the flag and the path); a write that fails after
/// the work is exit 3, naming the file.
#[cfg(feature = "render")]
fn check_plot_dir(dir: &std::path::Path) -> Result<(), Error> {
    let why = if dir.is_dir() {
        return Ok(());
    } else if dir.exists() {
        "is not a folder"
    } else {
        "no such folder (create it first)"
    };
    Err(InputError::new(format!("--plot-dir {}: {why}", dir.display())).into())
}
