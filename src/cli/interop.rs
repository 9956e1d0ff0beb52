//! `reconfcheck import visiblesim|trace` and `reconfcheck export
//! visiblesim`: VisibleSim files in and out (library: `reconfcheck::interop`).

use clap::{Args, Subcommand};
use reconfcheck::error::{Error, InputError, read_file, write_file};
use reconfcheck::interop::{self, GroundChoice, VsLattice};
use reconfcheck::schedule::{Length, Schedule};
use std::path::{Path, PathBuf};

/// How the imported structure meets the ground.
#[derive(Args, Clone, Debug)]
pub struct GroundArgs {
    /// The ground layer (VisibleSim's z). Default: the lowest occupied
    /// layer of the initial configuration rests on the ground.
    #[arg(long, value_name = "Z", conflicts_with = "no_ground")]
    ground: Option<i32>,
    /// No ground: a free-floating structure (connected when it is one piece).
    #[arg(long)]
    no_ground: bool,
}

impl GroundArgs {
    fn choice(&self) -> GroundChoice {
        match (self.ground, self.no_ground) {
            (_, true) => GroundChoice::None,
            (Some(z), false) => GroundChoice::Layer(z),
            (None, false) => GroundChoice::Lowest,
        }
    }
}

#[derive(Subcommand)]
pub enum ImportCommand {
    /// A VisibleSim configuration (config.xml) as a zero-step schedule.
    Visiblesim {
        /// The VisibleSim configuration file.
        config: PathBuf,
        /// The schedule to write.
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
        /// VisibleSim's grid: `fcc` (FCCLattice, Catoms3D's default; the
        /// default here) or `skewed-fcc` (SkewFCCLattice, seed 000's
        /// scaffold applications). The XML does not say which.
        #[arg(long, default_value = "fcc")]
        lattice: VsLattice,
        /// Lattice spacing d in millimetres (the 3D Catom: 3.6 mm).
        #[arg(long, default_value_t = 3.6, value_name = "MM")]
        spacing_mm: f64,
        /// Write the configuration's CSG target instead of its blocks: one
        /// module in every grid cell VisibleSim counts as inside the target.
        #[arg(long)]
        target: bool,
        #[command(flatten)]
        ground: GroundArgs,
    },
    /// A webots-visiblesim motion trace (CSV) as a schedule of rotations.
    Trace(TraceArgs),
}

#[derive(Args)]
pub struct TraceArgs {
    /// The trace (CSV: t_us, blockId, init/from/to/pivot cells, optional
    /// linkTo, linkFace).
    trace: PathBuf,
    /// The configuration the run started from; without it, the initial
    /// configuration is the movers' initial cells plus a static module at
    /// every pivot cell no mover accounts for.
    #[arg(long, value_name = "CONFIG.xml")]
    config: Option<PathBuf>,
    /// The schedule to write.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// VisibleSim's grid of the configuration file (the trace's cells are
    /// always FCCLattice's, our frame).
    #[arg(long, default_value = "fcc")]
    lattice: VsLattice,
    /// Duration of one rotation in µs (400 ms in webots-visiblesim runs):
    /// moves whose intervals overlap are grouped into one step.
    #[arg(long, default_value_t = 400_000, value_name = "US")]
    move_us: u64,
    /// One move per step, in trace order, instead of grouping.
    #[arg(long)]
    one_per_step: bool,
    /// Lattice spacing d in millimetres.
    #[arg(long, default_value_t = 3.6, value_name = "MM")]
    spacing_mm: f64,
    #[command(flatten)]
    ground: GroundArgs,
}

#[derive(Subcommand)]
pub enum ExportCommand {
    /// A schedule's configuration at a step as a VisibleSim config.xml.
    Visiblesim {
        /// The schedule.
        schedule: PathBuf,
        /// The configuration after this many steps (0: the initial one).
        /// Default: the final configuration.
        #[arg(long)]
        step: Option<usize>,
        /// VisibleSim's grid to write positions in (default: the one the
        /// schedule was imported with, else `fcc`).
        #[arg(long)]
        lattice: Option<VsLattice>,
        /// The configuration file to write.
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
}

fn spacing(mm: f64) -> Result<Length, Error> {
    if !(mm.is_finite() && mm > 0.0) {
        return Err(InputError::new(format!("--spacing-mm {mm} is not a positive length")).into());
    }
    Ok(Length::mm(mm))
}

fn read_config(path: &Path, lattice: VsLattice) -> Result<interop::VsConfig, Error> {
    let text = read_file(path, "VisibleSim configuration")?;
    Ok(interop::read_config(&text, path, lattice)?)
}

fn write_schedule(s: &Schedule, path: &Path) -> Result<(), Error> {
    s.validate().map_err(|e| e.in_file(path))?;
    write_file(path, s.to_json())
}

pub fn import(cmd: ImportCommand) -> Result<u8, Error> {
    match cmd {
        ImportCommand::Visiblesim {
            config,
            output,
            lattice,
            spacing_mm,
            target,
            ground,
        } => {
            let d = spacing(spacing_mm)?;
            let mut cfg = read_config(&config, lattice)?;
            let cells = interop::target_cells(&cfg, lattice).map_err(|e| e.in_file(&config))?;
            if let Some(c) = &cells {
                eprintln!(
                    "{}: CSG target of {} cells ({} grid)",
                    config.display(),
                    c.len(),
                    lattice.name()
                );
            }
            if target {
                let Some(c) = cells else {
                    return Err(
                        InputError::new("--target: the configuration has no <csg> target")
                            .in_file(&config)
                            .into(),
                    );
                };
                cfg.blocks = c
                    .iter()
                    .enumerate()
                    .map(|(k, &cell)| interop::VsBlock {
                        id: k as u32 + 1,
                        position: lattice.to_grid(cell),
                        color: None,
                        orientation: None,
                        master: false,
                        line: 0,
                    })
                    .collect();
            }
            let mut s = interop::import_config(
                &cfg,
                lattice,
                ground.choice(),
                d,
                &config.display().to_string(),
            );
            if target {
                s.meta.insert("visiblesim_target".into(), true.into());
            }
            write_schedule(&s, &output)?;
            eprintln!(
                "{}: {} modules ({} grid) -> {}",
                config.display(),
                s.modules.len(),
                lattice.name(),
                output.display()
            );
            Ok(0)
        }
        ImportCommand::Trace(a) => import_trace(a),
    }
}

fn import_trace(a: TraceArgs) -> Result<u8, Error> {
    let d = spacing(a.spacing_mm)?;
    let cfg = match &a.config {
        Some(p) => Some((read_config(p, a.lattice)?, p.clone())),
        None => None,
    };
    let text = read_file(&a.trace, "motion trace")?;
    let rows = interop::read_trace(&text).map_err(|e| e.in_file(&a.trace))?;
    let opts = interop::TraceOptions {
        move_us: a.move_us,
        one_per_step: a.one_per_step,
        ground: a.ground.choice(),
        lattice: a.lattice,
        spacing: d,
    };
    let s = interop::trace_to_schedule(&rows, cfg.as_ref().map(|(c, _)| c), &opts)
        .map_err(|e| e.in_file(&a.trace))?;
    write_schedule(&s, &a.output)?;
    eprintln!(
        "{}: {} moves in {} steps, {} modules -> {}",
        a.trace.display(),
        s.move_count(),
        s.steps.len(),
        s.modules.len(),
        a.output.display()
    );
    Ok(0)
}

pub fn export(cmd: ExportCommand) -> Result<u8, Error> {
    let ExportCommand::Visiblesim {
        schedule,
        step,
        lattice,
        output,
    } = cmd;
    let s = Schedule::load(&schedule)?;
    let lattice = lattice.unwrap_or_else(|| {
        s.meta
            .get("visiblesim")
            .and_then(|v| v.get("lattice"))
            .and_then(|v| v.as_str())
            .and_then(|v| v.parse().ok())
            .unwrap_or_default()
    });
    let step = step.unwrap_or(s.steps.len());
    let xml = interop::export_config(&s, step, lattice).map_err(|e| e.in_file(&schedule))?;
    write_file(&output, xml)?;
    Ok(0)
}
