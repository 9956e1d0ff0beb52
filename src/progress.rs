//! Progress bars on standard error for long runs (certification of large
//! schedules, the b-study, the density study), in one style.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar over `len` units of work on stderr, drawn with `template`
/// (indicatif's syntax) when `shown`; otherwise a hidden bar that counts
/// without drawing, so callers advance it either way.
pub fn bar(shown: bool, len: usize, template: &str) -> ProgressBar {
    if !shown {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::stderr());
    bar.set_style(ProgressStyle::with_template(template).expect("valid template"));
    bar
}
