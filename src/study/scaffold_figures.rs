//! Seed 000 §5.4 (Figs. 11–16): the scaffold generator's reconfiguration
//! time and placement rate on the paper's canonical shapes, over sizes and
//! in both protocols, with the numbers the paper and the authors' own runs
//! publish beside ours.
//!
//! The canonical shapes are the authors' own targets (restated in
//! `models/shapes/authors/`, read as VisibleSim reads them), so that the
//! module counts are theirs: the cube of size N has exactly the modules of
//! their `results/main.dat`. The pyramid is §4's h-pyramid with h = N.

use crate::algorithms::scaffold::feed::Feed;
use crate::algorithms::scaffold::paper::Protocol;
use crate::algorithms::scaffold::{ShapeSpec, scaffold_schedule_fed};
use crate::error::InputError;
use crate::progress::Reporter;
use crate::schedule::{Event, Schedule};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The branch length of every run in the paper's §5.4.
pub const B: u32 = 6;

/// A canonical shape family of §5.4.1.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    Pyramid,
    Cube,
    Cylinder,
    HalfSphere,
    /// Fig. 15's cylinder of twice the height (size 6 only).
    StackedCylinder,
}

impl Family {
    /// The four shapes of Figs. 11–14, in the paper's order of time.
    pub const CANONICAL: [Family; 4] = [
        Family::HalfSphere,
        Family::Pyramid,
        Family::Cylinder,
        Family::Cube,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Family::Pyramid => "pyramid",
            Family::Cube => "cube",
            Family::Cylinder => "cylinder",
            Family::HalfSphere => "half-sphere",
            Family::StackedCylinder => "cylinder-stacked",
        }
    }

    /// The shape of size `n`: the h-pyramid with h = n, else the authors'
    /// target `{name}-{n}.xml` in `shapes` (`models/shapes/authors`).
    pub fn spec(self, n: u32, shapes: &Path) -> Result<ShapeSpec, InputError> {
        if self == Family::Pyramid {
            return Ok(ShapeSpec::Pyramid { h: n });
        }
        let path = shapes.join(format!("{}-{n}.xml", self.name()));
        if !path.is_file() {
            return Err(InputError::new(format!(
                "no {} of size {n}: the authors' targets are sizes {} (models/shapes/authors)",
                self.name(),
                if self == Family::StackedCylinder {
                    "6"
                } else {
                    "2 to 9"
                }
            ))
            .in_file(&path));
        }
        Ok(ShapeSpec::Csg { path })
    }
}

/// One generated schedule's figures.
#[derive(Clone, Debug)]
pub struct Run {
    pub family: Family,
    pub size: u32,
    pub protocol: Protocol,
    pub feed: Feed,
    pub steps: usize,
    pub modules: usize,
    /// Tile layers of the scaffold: Fig. 12's "height levels".
    pub levels: usize,
    /// Step at which the first tile root of the top layer is in place (the
    /// end of Eq. 6's critical path).
    pub top_root: usize,
    /// Modules placed in each step (Figs. 14–16).
    pub placed: Vec<usize>,
}

impl Run {
    /// Fig. 12: time steps per height level.
    pub fn steps_per_level(&self) -> f64 {
        self.steps as f64 / self.levels.max(1) as f64
    }

    /// Fig. 13: modules placed per time step, on average.
    pub fn modules_per_step(&self) -> f64 {
        self.modules as f64 / self.steps.max(1) as f64
    }
}

/// Modules placed in each step (index = step − 1): a module is placed at
/// the step of its last motion.
pub fn placed_per_step(s: &Schedule) -> Vec<usize> {
    let mut last: HashMap<u32, usize> = HashMap::new();
    for (k, step) in s.steps.iter().enumerate() {
        for e in &step.events {
            if matches!(e, Event::Rotate { .. }) {
                last.insert(e.module(), k);
            }
        }
    }
    let mut out = vec![0; s.steps.len()];
    for &k in last.values() {
        out[k] += 1;
    }
    out
}

/// Generates one shape in one protocol and feed, and takes its figures.
pub fn run(
    family: Family,
    size: u32,
    protocol: Protocol,
    feed: Feed,
    shapes: &Path,
) -> Result<Run, InputError> {
    let spec = family.spec(size, shapes)?;
    let s = scaffold_schedule_fed(&spec, B, protocol, feed)?;
    let meta = |k: &str| s.meta.get(k).and_then(|v| v.as_u64()).unwrap_or(0) as usize;
    let top_root = s
        .meta
        .get("layer_root_steps")
        .and_then(|v| v.as_array())
        .and_then(|a| a.last())
        .and_then(|v| v.as_u64())
        .unwrap_or(0) as usize;
    Ok(Run {
        family,
        size,
        protocol,
        feed,
        steps: s.steps.len(),
        modules: meta("scaffold_modules"),
        levels: meta("tile_layers"),
        top_root,
        placed: placed_per_step(&s),
    })
}

/// Every family × size × protocol, in that order, all with one feed.
pub fn sweep(
    families: &[Family],
    sizes: &[u32],
    protocols: &[Protocol],
    feed: Feed,
    shapes: &Path,
    progress: &Reporter,
) -> Result<Vec<Run>, InputError> {
    let n = (families.len() * sizes.len() * protocols.len()) as u64;
    progress.start("seed 000 figures", n);
    let mut out = Vec::new();
    for &f in families {
        for &n in sizes {
            for &p in protocols {
                out.push(run(f, n, p, feed, shapes)?);
                progress.advance(1);
            }
        }
    }
    progress.finish();
    Ok(out)
}

/// The numbers the paper and the authors' runs publish.
pub mod published {
    use super::Family;

    /// Eq. 6 at b = 6: `T = 16(b − 1)(h − 1)` time steps for the h-pyramid
    /// (the authors' `scaffolding_pyramid_async/time.dat` holds exactly
    /// these values).
    pub fn pyramid_steps(h: u32) -> usize {
        16 * (super::B as usize - 1) * (h as usize).saturating_sub(1)
    }

    /// Eq. 4 at b = 6: the h-pyramid's module count.
    pub fn pyramid_modules(h: u32) -> usize {
        let (b, h) = (super::B as i64, h as i64);
        (((12 * b - 2) * h.pow(3) + (27 - 12 * b) * h.pow(2) + 5 * h) / 6) as usize
    }

    /// The authors' cube runs (VisibleSim commit 1aa66fe4,
    /// `applicationsBin/scaffolding_cube/results/main.dat`): size N, time
    /// steps, modules. Size 6 is the paper's "nearly 600 time steps" cube.
    pub const AUTHORS_CUBE: [(u32, usize, usize); 8] = [
        (2, 100, 77),
        (3, 243, 414),
        (4, 349, 1194),
        (5, 492, 2679),
        (6, 597, 5007),
        (7, 746, 8480),
        (8, 844, 13196),
        (9, 1000, 19497),
    ];

    /// §5.4.2: "only 1,200 time steps for the sandcastle".
    pub const SANDCASTLE_STEPS: usize = 1200;

    /// Fig. 15's caption: the simple and stacked cylinders' curves
    /// "overlap until t = 380 time steps".
    pub const STACKED_OVERLAP_UNTIL: usize = 380;

    /// (time steps, modules) the paper or the authors publish for a shape,
    /// where they do.
    pub fn point(family: Family, size: u32) -> Option<(usize, usize)> {
        match family {
            Family::Pyramid => Some((pyramid_steps(size), pyramid_modules(size))),
            Family::Cube => AUTHORS_CUBE
                .iter()
                .find(|c| c.0 == size)
                .map(|&(_, t, n)| (t, n)),
            _ => None,
        }
    }
}

/// The step from which two placement curves differ (Fig. 15's overlap):
/// the first step whose cumulative counts differ by more than `tol` of the
/// smaller, or the shorter length.
pub fn overlap_until(a: &[usize], b: &[usize], tol: f64) -> usize {
    let (mut ca, mut cb) = (0usize, 0usize);
    for k in 0..a.len().min(b.len()) {
        ca += a[k];
        cb += b[k];
        let lo = ca.min(cb).max(1) as f64;
        if (ca as f64 - cb as f64).abs() > tol * lo {
            return k + 1;
        }
    }
    a.len().min(b.len())
}

/// The default folder of the authors' targets, relative to the crate.
pub fn default_shapes() -> PathBuf {
    PathBuf::from("models/shapes/authors")
}

/// A table of runs beside the published numbers (one line per run).
pub fn table(runs: &[Run]) -> String {
    use std::fmt::Write;
    let mut s = String::from(
        "shape             size protocol feed          modules  steps  levels  steps/level  modules/step  top root  published (steps, modules)\n",
    );
    for r in runs {
        let published = published::point(r.family, r.size)
            .map(|(t, n)| {
                format!(
                    "{t} ({:+.0} %), {n}{}",
                    (r.steps as f64 / t as f64 - 1.0) * 100.0,
                    if n == r.modules { " =" } else { " ≠" }
                )
            })
            .unwrap_or_else(|| "—".into());
        let _ = writeln!(
            s,
            "{:<17} {:>4} {:<8} {:<12} {:>8} {:>6} {:>7} {:>12.1} {:>13.2} {:>9}  {}",
            r.family.name(),
            r.size,
            r.protocol.name(),
            r.feed.name(),
            r.modules,
            r.steps,
            r.levels,
            r.steps_per_level(),
            r.modules_per_step(),
            r.top_root,
            published
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shapes() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("models/shapes/authors")
    }

    #[test]
    fn the_authors_small_cubes_and_the_pyramid_have_their_published_module_counts() {
        let runs = sweep(
            &[Family::Pyramid, Family::Cube],
            &[2, 3],
            &[Protocol::Paper],
            Feed::JustInTime,
            &shapes(),
            &Reporter::silent(),
        )
        .unwrap();
        for r in &runs {
            let (_, n) = published::point(r.family, r.size).unwrap();
            assert_eq!(r.modules, n, "{} {}", r.family.name(), r.size);
            assert_eq!(r.placed.iter().sum::<usize>(), r.modules);
            assert_eq!(r.placed.len(), r.steps);
        }
        // The pyramid of h tiles has h tile layers, and its top root comes
        // in at the end of the run, as Eq. 6's critical path ends the build.
        let p3 = &runs[1];
        assert_eq!((p3.family, p3.size, p3.levels), (Family::Pyramid, 3, 3));
        assert!(p3.top_root > 0 && p3.top_root <= p3.steps);
    }

    #[test]
    fn eq_6_gives_80_steps_per_tile_layer_and_eq_4_the_module_counts() {
        assert_eq!(published::pyramid_steps(2), 80);
        assert_eq!(published::pyramid_steps(9), 640);
        let n: Vec<usize> = (2..=9).map(published::pyramid_modules).collect();
        assert_eq!(n, [65, 250, 630, 1275, 2255, 3640, 5500, 7905]);
    }

    #[test]
    fn a_missing_size_is_refused_naming_the_file() {
        let e = Family::Cylinder.spec(12, &shapes()).unwrap_err();
        assert!(e.to_string().contains("cylinder-12.xml"), "{e}");
        let e = Family::StackedCylinder.spec(4, &shapes()).unwrap_err();
        assert!(e.to_string().contains("sizes 6"), "{e}");
    }

    #[test]
    fn curves_overlap_until_their_cumulative_counts_part() {
        let a = [1, 2, 3, 4, 4, 4];
        let b = [1, 2, 3, 4, 8, 8];
        assert_eq!(overlap_until(&a, &b, 0.05), 5);
        assert_eq!(overlap_until(&a, &a, 0.05), 6);
    }
}
