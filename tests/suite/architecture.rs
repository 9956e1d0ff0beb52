//! The layering, enforced: every library file is read, and each reference
//! to `crate::<module>` outside test code must point down the layer list of
//! `src/lib.rs`. A new back arrow fails the build's tests, naming the file,
//! the line and the rule.

use std::path::{Path, PathBuf};

/// The layers of `src/lib.rs`, lowest first. A module may use modules of a
/// lower rank only; the leaves (rank 0) use nothing but leaves.
const RANKS: &[(&str, u32)] = &[
    ("error", 0),
    ("number", 0),
    ("progress", 0),
    ("lattice", 1),
    ("schedule", 2),
    ("scenario", 2),
    ("geometry", 3),
    ("mechanics", 4),
    ("algorithms", 5),
    ("certify", 6),
    ("interop", 6),
    ("study", 7),
    ("render", 8),
    ("html", 8),
];

/// Arrows the ranks alone would allow but the design forbids: generators
/// never see the mechanics, and certification never sees the generators
/// (judgement belongs to the certifier, which must not plan).
const FORBIDDEN: &[(&str, &str)] = &[("algorithms", "mechanics"), ("certify", "algorithms")];

fn rank(module: &str) -> Option<u32> {
    RANKS.iter().find(|(m, _)| *m == module).map(|&(_, r)| r)
}

/// The top-level module a library file belongs to (`lib.rs`: none).
fn module_of(rel: &Path) -> Option<String> {
    let first = rel.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (name != "lib").then(|| name.to_string())
}

/// The code of a file without comments and without its test modules
/// (everything from a `#[cfg(test)]` that opens a module to the end: test
/// code may use any layer to build its cases).
fn production_code(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        let next = lines.get(i + 1).map(|l| l.trim_start()).unwrap_or("");
        if t.starts_with("#[cfg(test)]")
            && (next.starts_with("mod ") || next.starts_with("pub mod "))
        {
            break;
        }
        let code = match t.find("//") {
            Some(k) => &t[..k],
            None => t,
        };
        out.push((i + 1, code.to_string()));
    }
    out
}

/// The top-level modules a line of code names through `crate::`, including
/// those inside a `crate::{a::X, b::Y}` group.
fn targets(code: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(k) = rest.find("crate::") {
        rest = &rest[k + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // Top-level entries of the group: at depth 0, after '{' or ','.
            let mut depth = 0;
            let mut start = true;
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && !c.is_whitespace() => {
                        start = false;
                        out.push(ident(&group[i..]));
                    }
                    _ => {}
                }
            }
        } else {
            out.push(ident(rest));
        }
    }
    out.retain(|t| !t.is_empty() && t != "self");
    out
}

/// Every arrow that breaks the layering in one file's text.
fn violations(module: &str, file: &str, text: &str) -> Vec<String> {
    let Some(from) = rank(module) else {
        return vec![format!(
            "{file}: module '{module}' has no layer in RANKS (add it)"
        )];
    };
    let mut out = Vec::new();
    for (line, code) in production_code(text) {
        for target in targets(&code) {
            if target == module {
                continue;
            }
            let Some(to) = rank(&target) else {
                out.push(format!("{file}:{line}: unknown module crate::{target}"));
                continue;
            };
            if to >= from && !(from == 0 && to == 0) {
                out.push(format!(
                    "{file}:{line}: {module} (layer {from}) uses {target} (layer {to}): \
                     a layer may only use those below it"
                ));
            } else if FORBIDDEN.contains(&(module, target.as_str())) {
                out.push(format!("{file}:{line}: {module} must not use {target}"));
            }
        }
    }
    out
}

fn library_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            library_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn every_library_module_uses_only_the_layers_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    library_files(&src, &mut files);
    files.sort();
    let mut found = Vec::new();
    let mut read = 0;
    for f in &files {
        let rel = f.strip_prefix(&src).unwrap();
        // The binary (main.rs and its cli/ modules) is the top: it may use
        // every layer, and no library file can name it.
        if rel == Path::new("main.rs") || rel.starts_with("cli") {
            continue;
        }
        let Some(module) = module_of(rel) else {
            continue;
        };
        let text = std::fs::read_to_string(f).unwrap();
        assert!(
            !text.contains("crate::cli") && !text.contains("mod cli"),
            "{}: the library must not name the CLI",
            rel.display()
        );
        found.extend(violations(&module, &rel.display().to_string(), &text));
        read += 1;
    }
    assert!(
        read > 50,
        "read {read} library files: is src/ where it should be?"
    );
    assert!(found.is_empty(), "layering broken:\n{}", found.join("\n"));
}

#[test]
fn a_back_arrow_is_caught_and_test_code_is_not_counted() {
    let text = "use crate::lattice::Cell;\n\
                // crate::certify in a comment does not count\n\
                pub fn f() { crate::certify::certify(); }\n\
                #[cfg(test)]\n\
                mod tests { use crate::certify::World; }\n";
    let v = violations("geometry", "geometry/x.rs", text);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(
        v[0].starts_with("geometry/x.rs:3: geometry (layer 3) uses certify"),
        "{v:?}"
    );
    // The arrows the ranks allow but the design forbids.
    let v = violations(
        "certify",
        "certify/x.rs",
        "use crate::algorithms::branch;\n",
    );
    assert_eq!(v, ["certify/x.rs:1: certify must not use algorithms"]);
    assert_eq!(
        violations("algorithms", "a.rs", "use crate::mechanics::Model;").len(),
        1
    );
    // Grouped imports are read entry by entry.
    let v = violations(
        "lattice",
        "l.rs",
        "use crate::{error::InputError, geometry::{A, B}};",
    );
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(v[0].contains("uses geometry"), "{v:?}");
    // Nothing may use the pictures, and leaves stay leaves.
    assert_eq!(
        violations("study", "s.rs", "crate::render::save(x)").len(),
        1
    );
    assert_eq!(
        violations("error", "e.rs", "use crate::lattice::Cell;").len(),
        1
    );
    assert!(violations("error", "e.rs", "use crate::number::positive;").is_empty());
    assert_eq!(
        violations("nowhere", "n.rs", "").len(),
        1,
        "an unranked module is named"
    );
}
