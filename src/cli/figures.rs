//! `reconfcheck plot --figure N`: seed 000's §5.4 figures (Figs. 11–16),
//! our runs beside the published numbers, drawn and printed as a table.

use reconfcheck::algorithms;
use reconfcheck::algorithms::scaffold::feed::Feed;
use reconfcheck::algorithms::scaffold::paper::Protocol;
use reconfcheck::error::{Error, InputError};
use reconfcheck::render;
use reconfcheck::render::scaffold_figures::Metric;
use reconfcheck::scenario::Scenario;
use reconfcheck::study::scaffold_figures::{self as figs, Family, published};
use std::path::{Path, PathBuf};

/// The figure's parameters, validated.
pub struct Figure {
    pub number: u32,
    pub sizes: Vec<u32>,
    pub shapes: PathBuf,
    pub scenarios: Vec<PathBuf>,
    pub output: PathBuf,
    pub progress: bool,
    pub feed: Feed,
}

/// Parses `A..B` or `A,B,…` (sizes 2 to 9: the authors' targets).
pub fn parse_sizes(s: &str) -> Result<Vec<u32>, InputError> {
    let bad = || InputError::new(format!("--sizes '{s}': expected A..B or A,B,… within 2..9"));
    let v: Vec<u32> = if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        (a..=b).collect()
    } else {
        s.split(',')
            .map(|t| t.trim().parse().map_err(|_| bad()))
            .collect::<Result<_, _>>()?
    };
    if v.is_empty() || v.iter().any(|n| !(2..=9).contains(n)) {
        return Err(bad());
    }
    Ok(v)
}

pub fn draw(f: Figure) -> Result<u8, Error> {
    let progress = super::progress::reporter(f.progress, 1);
    let both = [Protocol::Paper, Protocol::Safe];
    match f.number {
        11..=13 => {
            let runs = figs::sweep(
                &Family::CANONICAL,
                &f.sizes,
                &both,
                f.feed,
                &f.shapes,
                &progress,
            )?;
            print!("{}", figs::table(&runs));
            let metric = match f.number {
                11 => Metric::Steps,
                12 => Metric::StepsPerLevel,
                _ => Metric::ModulesPerStep,
            };
            render::scaffold_figures::draw(&runs, metric, &f.output)?;
        }
        14 => {
            let runs = figs::sweep(
                &Family::CANONICAL,
                &[6],
                &both,
                f.feed,
                &f.shapes,
                &progress,
            )?;
            print!("{}", figs::table(&runs));
            let curves = paper_curves(&runs);
            let marks: Vec<(String, f64)> = [Family::Pyramid, Family::Cube]
                .iter()
                .filter_map(|&fam| {
                    published::point(fam, 6)
                        .map(|(t, _)| (format!("{} published: {t}", fam.name()), t as f64))
                })
                .collect();
            render::placed_plot(
                &curves,
                "Fig. 14, size 6, paper protocol",
                &marks,
                &f.output,
            )?;
        }
        15 => {
            let runs = figs::sweep(
                &[Family::Cylinder, Family::StackedCylinder],
                &[6],
                &[Protocol::Paper],
                f.feed,
                &f.shapes,
                &progress,
            )?;
            print!("{}", figs::table(&runs));
            let until = figs::overlap_until(&runs[0].placed, &runs[1].placed, 0.02);
            println!(
                "the curves overlap (cumulative counts within 2 %) until step {until}; the paper: until t = {}",
                published::STACKED_OVERLAP_UNTIL
            );
            let marks = [(
                format!("paper: overlap until {}", published::STACKED_OVERLAP_UNTIL),
                published::STACKED_OVERLAP_UNTIL as f64,
            )];
            render::placed_plot(
                &paper_curves(&runs),
                "Fig. 15, cylinder and stacked cylinder",
                &marks,
                &f.output,
            )?;
        }
        16 => {
            let scenarios = if f.scenarios.is_empty() {
                vec![
                    PathBuf::from("scenarios/sandcastle-eager.toml"),
                    PathBuf::from("scenarios/sandcastle-paper.toml"),
                    PathBuf::from("scenarios/sandcastle.toml"),
                ]
            } else {
                f.scenarios.clone()
            };
            let mut curves = Vec::new();
            for p in &scenarios {
                let sc = Scenario::load(p)?;
                let s = algorithms::generate(&sc)?;
                let v = figs::placed_per_step(&s);
                println!(
                    "{}: {} modules placed in {} steps (paper: ≈ {})",
                    sc.name,
                    v.iter().sum::<usize>(),
                    v.len(),
                    published::SANDCASTLE_STEPS
                );
                curves.push((sc.name.clone(), v));
            }
            let marks = [(
                format!("paper: ≈ {}", published::SANDCASTLE_STEPS),
                published::SANDCASTLE_STEPS as f64,
            )];
            render::placed_plot(&curves, "Fig. 16, sandcastle", &marks, &f.output)?;
        }
        n => {
            return Err(InputError::new(format!(
                "--figure {n}: seed 000's figures drawn here are 11 to 16"
            ))
            .into());
        }
    }
    eprintln!("wrote {}", f.output.display());
    Ok(0)
}

/// The paper protocol's placement curves of `runs`, labelled by shape.
fn paper_curves(runs: &[figs::Run]) -> Vec<(String, Vec<usize>)> {
    runs.iter()
        .filter(|r| r.protocol == Protocol::Paper)
        .map(|r| {
            (
                format!("{} {} ({} modules)", r.family.name(), r.size, r.modules),
                r.placed.clone(),
            )
        })
        .collect()
}

/// The authors' targets folder: `dir` if given, else
/// `models/shapes/authors` under the current directory.
pub fn shapes_dir(dir: Option<&Path>) -> PathBuf {
    dir.map(Path::to_path_buf)
        .unwrap_or_else(figs::default_shapes)
}
