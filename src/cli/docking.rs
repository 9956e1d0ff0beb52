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
}

pub fn run(a: Args) -> Result<u8, Error> {
    if a.seeds == 0 || !(a.factor.is_finite() && a.factor > 0.0) {
        return Err(
            InputError::new("docking-study needs --seeds ≥ 1 and a positive --factor").into(),
        );
    }
    let messages = study::messages(&a.models, a.seeds)?;
    let curves = study::availability(&a.models, a.factor, a.seeds)?;
    let naive = study::naive_orders(&a.models, a.factor, 0)?;
    print!("{}", study::tables(&messages, &curves, &naive));
    if let Some(p) = a.json {
        let v = serde_json::json!({"fig10": messages, "fig11": curves, "naive": naive});
        write_file(&p, serde_json::to_string_pretty(&v).expect("serialises"))?;
    }
    Ok(0)
}
