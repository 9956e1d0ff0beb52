//! Progress bars on standard error (indicatif), for the library's
//! [`Progress`] reports: one style for every long run.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use reconfcheck::progress::{Progress, Reporter};
use std::io::IsTerminal;
use std::sync::{Arc, Mutex};

/// Draws each phase the library starts as a bar, when standard error is a
/// terminal and the phase has at least `min_len` units (short runs finish
/// before a bar would be read).
pub struct Bars {
    bar: Mutex<Option<ProgressBar>>,
    min_len: u64,
}

/// A reporter drawing bars, or a silent one when `wanted` is false or
/// standard error is not a terminal.
pub fn reporter(wanted: bool, min_len: u64) -> Reporter {
    if wanted && std::io::stderr().is_terminal() {
        Reporter::to(Arc::new(Bars {
            bar: Mutex::new(None),
            min_len,
        }))
    } else {
        Reporter::silent()
    }
}

impl Progress for Bars {
    fn start(&self, label: &str, len: u64) {
        let mut slot = self.bar.lock().expect("progress lock");
        if let Some(old) = slot.take() {
            old.finish_and_clear();
        }
        if len >= self.min_len {
            let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} ({per_sec}, eta {eta})")
                    .expect("valid template"),
            );
            bar.set_message(label.to_string());
            *slot = Some(bar);
        }
    }

    fn advance(&self, n: u64) {
        if let Some(bar) = self.bar.lock().expect("progress lock").as_ref() {
            bar.inc(n);
        }
    }

    fn finish(&self) {
        if let Some(bar) = self.bar.lock().expect("progress lock").take() {
            bar.finish_and_clear();
        }
    }
}
