//! `derive-moves`: search the stored atom sequences again (the expanded
//! model's SLIDE, the contracted model's four 1-TUNNELs) and write them,
//! or check the stored ones against the search. The library never trusts
//! the files: it replays them on every load (`geometry::stored_move`);
//! this command is how they are made.

use reconfcheck::error::{Error, InputError, write_file};
use reconfcheck::geometry::stored_move::StoredId;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Compare the search's result with the stored sequence instead of
    /// writing it: exit 1 if any differs.
    #[arg(long)]
    check: bool,
    /// Only this move (repeatable): slide-expanded, tunnel-contracted-alone,
    /// tunnel-contracted-leg-in, tunnel-contracted-leg-out,
    /// tunnel-contracted-both-legs. Default: all of them.
    #[arg(long = "move", value_name = "NAME")]
    moves: Vec<String>,
    /// The folder to write the files to, made if missing (default: the
    /// repository's models/moves, relative to the current directory).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<u8, Error> {
    let mut chosen = Vec::new();
    for name in &a.moves {
        let id = StoredId::ALL
            .into_iter()
            .find(|id| id.name() == name)
            .ok_or_else(|| {
                let known: Vec<&str> = StoredId::ALL.iter().map(|id| id.name()).collect();
                InputError::new(format!(
                    "derive-moves --move: no stored move '{name}' (known: {})",
                    known.join(", ")
                ))
            })?;
        chosen.push(id);
    }
    if chosen.is_empty() {
        chosen = StoredId::ALL.to_vec();
    }
    let dir = a.out.unwrap_or_else(|| PathBuf::from("models/moves"));
    // The folder is made before the searches (a minute each), so a path
    // that cannot be one fails at once rather than after them.
    if !a.check {
        std::fs::create_dir_all(&dir).map_err(|source| Error::Write {
            path: dir.clone(),
            source,
        })?;
    }
    let mut differ = 0;
    for id in chosen {
        eprintln!(
            "searching {} (bidirectional; up to a minute each in a release build) …",
            id.name()
        );
        let t = Instant::now();
        let found = id.derive().ok_or_else(|| {
            InputError::new(format!(
                "the search found no {} within its bounds",
                id.name()
            ))
        })?;
        let ops: usize = found.steps.iter().map(Vec::len).sum();
        eprintln!(
            "found: {ops} operations in {} parallel steps (2D slice), {} states, {:.1} s",
            found.steps.len(),
            found.states_explored,
            t.elapsed().as_secs_f64()
        );
        if a.check {
            let file = id.file().0;
            if id.load()? == found {
                println!("{file}: the stored sequence is what the search finds");
            } else {
                println!("{file}: the stored sequence differs from what the search finds");
                differ += 1;
            }
            continue;
        }
        let out = dir.join(format!("{}.json", id.name()));
        let json = serde_json::to_string_pretty(&found).expect("a stored move serialises") + "\n";
        write_file(&out, json)?;
        println!("wrote {}", out.display());
    }
    Ok(u8::from(differ > 0))
}
