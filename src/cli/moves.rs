//! `derive-moves`: search the stored atom sequences again (the expanded
//! model's SLIDE) and write them, or check the stored ones against the
//! search. The library never trusts the file: it replays it on every load
//! (`geometry::stored_move`); this command is how the file is made.

use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::geometry::stored_move::{
    EXPANDED_SLIDE_FILE, StoredMove, derive_expanded_slide, expanded_slide_text,
};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Compare the search's result with the stored sequence instead of
    /// writing it: exit 1 if they differ.
    #[arg(long)]
    check: bool,
    /// Where to write the sequence (default: the repository's
    /// models/moves/slide-expanded.json, relative to the current directory).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<u8, Error> {
    eprintln!(
        "searching the expanded model's SLIDE (bidirectional, up to 600,000 states; about a minute in a release build) …"
    );
    let t = Instant::now();
    let found = derive_expanded_slide()
        .ok_or_else(|| InputError::new("the search found no expanded SLIDE within its bounds"))?;
    let ops: usize = found.steps.iter().map(Vec::len).sum();
    eprintln!(
        "found: {ops} operations in {} parallel steps (2D slice), {} states, {:.1} s",
        found.steps.len(),
        found.states_explored,
        t.elapsed().as_secs_f64()
    );
    if a.check {
        let stored = StoredMove::parse(expanded_slide_text(), EXPANDED_SLIDE_FILE)?;
        if stored == found {
            println!("{EXPANDED_SLIDE_FILE}: the stored sequence is what the search finds");
            return Ok(0);
        }
        println!("{EXPANDED_SLIDE_FILE}: the stored sequence differs from what the search finds");
        return Ok(1);
    }
    let out = a.out.unwrap_or_else(|| PathBuf::from(EXPANDED_SLIDE_FILE));
    let text = serde_json::to_string_pretty(&found).expect("a stored move serialises") + "\n";
    write_file(&out, text)?;
    println!("wrote {}", out.display());
    Ok(0)
}
