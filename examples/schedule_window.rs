//! A window of a long schedule as a schedule of its own
//! ([`reconfcheck::certify::window`]): the configuration after its first
//! `START` steps, then its next `COUNT` steps, numbered from 1. The speed
//! work of issue #20 measures on one (`docs/mechanics.md`).
//!
//! `cargo run --release --example schedule_window -- SCHEDULE START COUNT OUT`
use reconfcheck::schedule::Schedule;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [path, start, count, out] = args.as_slice() else {
        eprintln!("usage: schedule_window SCHEDULE START COUNT OUT");
        return ExitCode::from(2);
    };
    let (Ok(start), Ok(count)) = (start.parse::<usize>(), count.parse::<usize>()) else {
        eprintln!("START and COUNT are step counts");
        return ExitCode::from(2);
    };
    let made = Schedule::load(std::path::Path::new(path))
        .and_then(|s| reconfcheck::certify::window(s, start, count));
    match made {
        Ok(w) => match std::fs::write(out, w.to_json()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("{out}: {e}");
                ExitCode::from(2)
            }
        },
        Err(e) => {
            eprintln!("{path}: {e}");
            ExitCode::from(2)
        }
    }
}
