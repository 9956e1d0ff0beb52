//! Progress on standard error for the library's [`Progress`] reports:
//! bars (indicatif) on a terminal, a plain line every half minute
//! elsewhere, one style for every long run.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use reconfcheck::progress::{Progress, Reporter};
use std::io::{IsTerminal, Write};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Draws each phase the library starts as a bar, when standard error is a
/// terminal and the phase has at least `min_len` units (short runs finish
/// before a bar would be read).
pub struct Bars {
    bar: Mutex<Option<ProgressBar>>,
    min_len: u64,
}

/// A reporter drawing bars on a terminal, or writing a plain line now and
/// then ([`Lines`]) when standard error is a file or a pipe (a CI log, a
/// run in the background); silent when `wanted` is false.
pub fn reporter(wanted: bool, min_len: u64) -> Reporter {
    if !wanted {
        Reporter::silent()
    } else if std::io::stderr().is_terminal() {
        Reporter::to(Arc::new(Bars {
            bar: Mutex::new(None),
            min_len,
        }))
    } else {
        Reporter::to(Arc::new(Lines::new(
            LINE_EVERY,
            Box::new(std::io::stderr()),
        )))
    }
}

/// How often [`Lines`] writes: a run shorter than this writes nothing.
const LINE_EVERY: Duration = Duration::from_secs(30);

/// Progress without a terminal: one line on standard error per `every`
/// of a phase ("certifying: 120/1235 steps (9 %), 2 min 0 s"), none for a
/// phase that ends sooner, so short runs and their logs stay as they were.
pub struct Lines {
    every: Duration,
    phase: Mutex<Phase>,
    out: Mutex<Box<dyn Write + Send>>,
}

struct Phase {
    label: String,
    len: u64,
    done: u64,
    started: Instant,
    last: Instant,
}

impl Lines {
    pub fn new(every: Duration, out: Box<dyn Write + Send>) -> Lines {
        let now = Instant::now();
        Lines {
            every,
            out: Mutex::new(out),
            phase: Mutex::new(Phase {
                label: String::new(),
                len: 0,
                done: 0,
                started: now,
                last: now,
            }),
        }
    }
}

impl Progress for Lines {
    fn start(&self, label: &str, len: u64) {
        let now = Instant::now();
        *self.phase.lock().expect("progress lock") = Phase {
            label: label.to_string(),
            len,
            done: 0,
            started: now,
            last: now,
        };
    }

    fn advance(&self, n: u64) {
        let mut p = self.phase.lock().expect("progress lock");
        p.done += n;
        if p.last.elapsed() >= self.every {
            p.last = Instant::now();
            let secs = p.started.elapsed().as_secs();
            let percent = (100 * p.done).checked_div(p.len).unwrap_or(0);
            let mut out = self.out.lock().expect("progress lock");
            // A log that cannot be written must not stop the run.
            let _ = writeln!(
                out,
                "{}: {}/{} ({percent} %), {} min {} s",
                p.label,
                p.done,
                p.len,
                secs / 60,
                secs % 60
            );
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A writer the test can read back.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);

    impl Write for Shared {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    fn text(s: &Shared) -> String {
        String::from_utf8(s.0.lock().unwrap().clone()).unwrap()
    }

    #[test]
    fn without_a_terminal_a_long_phase_writes_plain_lines_and_a_short_one_none() {
        let out = Shared::default();
        let due = Lines::new(Duration::ZERO, Box::new(out.clone()));
        due.start("certifying", 8);
        due.advance(2);
        due.advance(4);
        let t = text(&out);
        assert!(t.starts_with("certifying: 2/8 (25 %), 0 min"), "{t}");
        assert!(
            t.lines()
                .nth(1)
                .unwrap()
                .starts_with("certifying: 6/8 (75 %)"),
            "{t}"
        );
        let quiet = Shared::default();
        let not_due = Lines::new(Duration::from_secs(3600), Box::new(quiet.clone()));
        not_due.start("certifying", 8);
        not_due.advance(8);
        assert_eq!(text(&quiet), "");
    }
}
