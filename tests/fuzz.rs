//! Bad input never panics: random edits of valid schedules (one to three of:
//! a value replaced by one of another kind or an extreme one, a key or an
//! element deleted, a step duplicated) are either refused as input errors
//! naming the file or certified with a verdict — through every check,
//! collision sweeps and mechanics included. `PROPTEST_CASES=20000 cargo
//! test --test fuzz` searches longer.

use proptest::prelude::*;
use reconfcheck::algorithms::random_walk::{WalkParams, walk};
use reconfcheck::certify::{Options, certify};
use reconfcheck::schedule::Schedule;
use serde_json::{Value, json};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

/// A small valid FCC walk, and the square-lattice U-shape of seed 003.
fn originals() -> Vec<Value> {
    let p = WalkParams {
        width: 4,
        depth: 4,
        walkers: 3,
        steps: 6,
        activity: 0.8,
        seed: 11,
        geometric: false,
    };
    let fcc = walk(&p, &|_, _, _| true);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenario = reconfcheck::scenario::Scenario::load(&root.join("scenarios/u-shape-pas.toml"))
        .expect("bundled scenario");
    let square = reconfcheck::algorithms::generate(&scenario).expect("generates");
    [fcc, square]
        .iter()
        .map(|s| serde_json::from_str(&s.to_json()).unwrap())
        .collect()
}

/// Paths to every value in `v` (object keys and array indices).
fn paths(v: &Value, prefix: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    out.push(prefix.clone());
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                prefix.push(json!(k));
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                prefix.push(json!(i));
                paths(x, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(v, |v, k| match k {
        Value::String(k) => &mut v[k.as_str()],
        _ => &mut v[k.as_u64().unwrap() as usize],
    })
}

/// Values that break assumptions: other kinds, zero, negatives, extremes.
fn replacements() -> Vec<Value> {
    vec![
        json!(null),
        json!(0),
        json!(-1),
        json!(1),
        json!(7),
        json!(3.5),
        json!(-2147483648i64),
        json!(2147483647i64),
        json!(4294967295u64),
        json!(1e300),
        json!("x"),
        json!(""),
        json!([]),
        json!([0, 0]),
        json!([0, 0, 0, 0]),
        json!({}),
        json!(true),
    ]
}

fn mutate(mut v: Value, what: usize, pick: prop::sample::Index, with: usize) -> Value {
    let mut all = Vec::new();
    paths(&v, &mut Vec::new(), &mut all);
    let path = pick.get(&all[1..]).clone();
    match what {
        // Replace the value.
        0 => *at(&mut v, &path) = replacements()[with % replacements().len()].clone(),
        // Delete it from its object or array.
        1 => {
            let (last, parent) = path.split_last().unwrap();
            match (at(&mut v, parent), last) {
                (Value::Object(m), Value::String(k)) => {
                    m.remove(k);
                }
                (Value::Array(a), Value::Number(i)) => {
                    a.remove(i.as_u64().unwrap() as usize);
                }
                _ => {}
            }
        }
        // Duplicate a step (its moves start from cells already left).
        _ => {
            if let Some(steps) = v["steps"].as_array_mut().filter(|s| !s.is_empty()) {
                let k = with % steps.len();
                let s = steps[k].clone();
                steps.insert(k, s);
            }
        }
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn edited_schedules_are_refused_or_certified_never_a_panic(
        which in 0usize..2,
        edits in prop::collection::vec((0usize..3, any::<prop::sample::Index>(), 0usize..64), 1..4),
    ) {
        let v = edits
            .into_iter()
            .fold(originals().swap_remove(which), |v, (what, pick, with)| mutate(v, what, pick, with));
        let text = serde_json::to_string(&v).unwrap();
        let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models");
        let model = if which == 0 { "catom-3.6mm.toml" } else { "sliding-square.toml" };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let s = Schedule::from_json(&text, Path::new("edited.json"))?;
            let opts = Options { model: Some(models.join(model)), ..Default::default() };
            // As the CLI does: an error inside a step names the step and the
            // module; the file is the caller's to add.
            certify(&s, &opts).map(|r| r.certified).map_err(|e| e.in_file("edited.json"))
        }));
        match outcome {
            Ok(Ok(_)) => {}
            Ok(Err(e)) => prop_assert!(e.to_string().contains("edited.json"), "{e}"),
            Err(_) => prop_assert!(false, "panicked on {text}"),
        }
    }
}
