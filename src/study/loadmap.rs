//! The load map of one step of a schedule (`reconfcheck loadmap`).

use crate::certify::load_check::replay;
use crate::error::{Error, InputError};
use crate::mechanics::Model;
use crate::mechanics::analysis::Critical;
use crate::schedule::Schedule;
use std::path::Path;

/// Replays `schedule` to `step` (1-based; `steps + 1` is the final
/// configuration), analyses it with `model` and writes the load map to
/// `path`. Returns a one-line summary.
pub fn render_step(
    schedule: &Schedule,
    model: &Model,
    step: usize,
    path: &Path,
) -> Result<String, Error> {
    let last = schedule.steps.len() + 1;
    if step == 0 || step > last {
        return Err(InputError::new(format!("step must be in 1..={last}, got {step}")).into());
    }
    let mut picture = None;
    let mut summary = String::new();
    // Stop early: a truncated copy of the schedule replays only what is needed.
    let mut upto = schedule.clone();
    upto.steps.truncate(step.min(schedule.steps.len()));
    let wanted = if step == last {
        upto.steps.len() + 1
    } else {
        step
    };
    replay(&upto, model, true, |k, s, a, _| {
        if k != wanted {
            return;
        }
        let critical = match a.critical {
            Some(Critical::Link(i)) => s.describe(&s.links[i]),
            Some(Critical::Pivot(i)) => {
                format!("pivot of mover {}", s.hanging[a.pivots[i].hanging].mover)
            }
            None => "-".into(),
        };
        summary = format!(
            "step {step}: {} modules, {} connectors, max utilisation {:.4} at {critical}, {:?}",
            s.bodies.len(),
            s.links.len(),
            a.max_utilisation,
            a.verdict()
        );
        let title = format!(
            "{}: step {step}, max utilisation {:.3} ({:?})",
            model.name,
            a.max_utilisation,
            a.verdict()
        );
        picture = Some(crate::render::loadmap_svg(s, a, &title));
    })?;
    let svg = picture
        .expect("the wanted step is replayed")
        .map_err(|e| Error::Render {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    crate::render::save(&svg, path, 1.0)?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algorithms::branch::branch_schedule;

    #[test]
    fn a_load_map_of_a_branch_step_is_written_and_names_the_root() {
        let s = branch_schedule(3, 3.6).unwrap();
        let dir = std::env::temp_dir().join(format!("reconfcheck-loadmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("map.png");
        let summary = render_step(&s, &Model::default_catom(), s.steps.len(), &p).unwrap();
        assert!(summary.contains("connector 0–1"), "{summary}");
        assert_eq!(&std::fs::read(&p).unwrap()[1..4], b"PNG");
        let svg = dir.join("map.svg");
        render_step(&s, &Model::default_catom(), s.steps.len() + 1, &svg).unwrap();
        assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
        assert!(render_step(&s, &Model::default_catom(), 0, &p).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
