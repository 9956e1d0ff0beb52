//! How far a long run is (certification of large schedules, the b-study,
//! the density study). The library reports through [`Progress`]; what is
//! drawn, and where, is the caller's business: the command line draws
//! bars on a terminal, tests count, everything else ignores it.

use std::fmt;
use std::sync::Arc;

/// A listener for progress. Called from worker threads, hence `Sync`.
pub trait Progress: Send + Sync {
    /// A phase of `len` units of work begins; `label` names it ("certifying",
    /// "b = 6", …).
    fn start(&self, label: &str, len: u64) {
        let _ = (label, len);
    }
    /// `n` more units of the current phase are done.
    fn advance(&self, n: u64);
    /// The current phase is over.
    fn finish(&self) {}
}

/// A shared, optional [`Progress`] listener to pass around in options:
/// silent by default.
#[derive(Clone, Default)]
pub struct Reporter(Option<Arc<dyn Progress>>);

impl Reporter {
    /// A reporter that tells `listener`.
    pub fn to(listener: Arc<dyn Progress>) -> Reporter {
        Reporter(Some(listener))
    }

    /// A reporter that tells nobody.
    pub fn silent() -> Reporter {
        Reporter(None)
    }

    pub fn start(&self, label: &str, len: u64) {
        if let Some(p) = &self.0 {
            p.start(label, len);
        }
    }

    pub fn advance(&self, n: u64) {
        if let Some(p) = &self.0 {
            p.advance(n);
        }
    }

    pub fn finish(&self) {
        if let Some(p) = &self.0 {
            p.finish();
        }
    }
}

impl fmt::Debug for Reporter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "Reporter(listening)"
        } else {
            "Reporter(silent)"
        })
    }
}
