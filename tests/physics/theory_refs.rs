//! The theory the code cites is in the repository, and every citation of it resolves.
//!
//! Doc comments, tests and the README cite docs/theory.md by section: `§5`, `§3.2`, ranges
//! `§2.1–§2.4`, and lists `§§2.1-2.3` or `§§4.2, 4.5`. This test reads every tracked file
//! (`git ls-files`; the directory tree without `target/` and `.git/` where there is no git),
//! collects every `§` citation whatever precedes it, and fails, listing all of them, if one names
//! no section heading of docs/theory.md. Inside docs/theory.md itself every `§` outside a
//! heading is a cross-reference and must resolve too (sections of other papers are written
//! "Sec. n" there). It also fails if a tracked file points at the shared folder the theory
//! was brought over from, or names the theory by its old file name outside `src/`.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

const THEORY: &str = "docs/theory.md";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The repository's tracked files, relative to its root with `/` separators.
fn tracked_files() -> Vec<String> {
    let git = Command::new("git").args(["ls-files", "-z"]).current_dir(root()).output();
    match git {
        Ok(out) if out.status.success() && !out.stdout.is_empty() => String::from_utf8(out.stdout)
            .expect("git ls-files gives UTF-8 paths")
            .split('\0')
            .filter(|p| !p.is_empty())
            .map(str::to_owned)
            .collect(),
        _ => {
            let mut files = Vec::new();
            walk(&root(), "", &mut files);
            files
        }
    }
}

fn walk(dir: &Path, prefix: &str, files: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display())) {
        let entry = entry.unwrap();
        let name = entry.file_name().to_string_lossy().into_owned();
        let rel = format!("{prefix}{name}");
        let kind = entry.file_type().unwrap();
        if kind.is_dir() {
            if prefix.is_empty() && (name == "target" || name == ".git") {
                continue;
            }
            walk(&entry.path(), &format!("{rel}/"), files);
        } else if kind.is_file() {
            files.push(rel);
        }
    }
}

/// Parses a section number (`5`, `3.2`, `10`) at the start of `s`: digits, then `.digits` as
/// long as a digit follows the dot (so a full stop after `§2.7.` is not part of it). Returns
/// the number and the rest of `s`.
fn section_number(s: &str) -> Option<(&str, &str)> {
    let bytes = s.as_bytes();
    let digits = |from: usize| from + bytes[from..].iter().take_while(|b| b.is_ascii_digit()).count();
    let mut end = digits(0);
    if end == 0 {
        return None;
    }
    while end + 1 < bytes.len() && bytes[end] == b'.' && bytes[end + 1].is_ascii_digit() {
        end = digits(end + 1);
    }
    Some((&s[..end], &s[end..]))
}

/// Every section cited in `line`: after `§` one number, after `§§` a list of numbers joined by
/// `-`, `–`, `,` or `and`. A `§` followed by no number (the sign named in prose) cites nothing.
fn citations(line: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find('§') {
        rest = &rest[at + '§'.len_utf8()..];
        let list = rest.starts_with('§');
        if list {
            rest = &rest['§'.len_utf8()..];
        }
        let Some((first, after)) = section_number(rest.trim_start()) else { continue };
        found.push(first.to_owned());
        rest = after;
        if !list {
            continue;
        }
        loop {
            let next = rest.trim_start_matches([' ', '-', '–', ',']);
            let next = next.strip_prefix("and ").unwrap_or(next);
            match section_number(next) {
                Some((n, after)) if next.len() < rest.len() => {
                    found.push(n.to_owned());
                    rest = after;
                }
                _ => break,
            }
        }
    }
    found
}

/// The section number of a Markdown heading line (`## §1 ...`, `### §1.4 ...`), if it has one.
fn heading_section(line: &str) -> Option<&str> {
    let text = line.strip_prefix('#')?.trim_start_matches('#').trim_start();
    section_number(text.strip_prefix('§')?).map(|(n, _)| n)
}

#[test]
fn the_citation_parser_reads_every_form_used() {
    assert_eq!(citations("OLD.md §9.4: per-order"), ["9.4"]);
    assert_eq!(citations("(docs/theory.md §2.1–§2.4)."), ["2.1", "2.4"]);
    assert_eq!(citations("routinely, §2.7."), ["2.7"]);
    assert_eq!(citations("§10, NaN policy; §0 and §1"), ["10", "0", "1"]);
    assert_eq!(citations("§§2.1-2.3 and §§4.2, 4.5 and 4.7"), ["2.1", "2.3", "4.2", "4.5", "4.7"]);
    assert_eq!(citations("Section numbers (§) are stable"), Vec::<String>::new());
    assert_eq!(heading_section("### §8.3 Sampling inside a triangle (Sec. 4 of [L20s])"), Some("8.3"));
    assert_eq!(heading_section("## §10 Known pitfalls"), Some("10"));
    assert_eq!(heading_section("Per bin compare (§9.5)"), None);
}

#[test]
fn every_cited_section_of_the_theory_exists() {
    let theory = std::fs::read_to_string(root().join(THEORY)).expect("docs/theory.md is in the repository");
    let mut sections = BTreeSet::new();
    for line in theory.lines() {
        if let Some(n) = heading_section(line) {
            assert!(sections.insert(n.to_owned()), "docs/theory.md has two headings for §{n}");
        }
    }
    for expected in ["0", "1", "1.4", "4.7", "9.4", "12"] {
        assert!(sections.contains(expected), "docs/theory.md has no heading §{expected}: {sections:?}");
    }

    let files = tracked_files();
    let mut cited = 0;
    let mut citing_files = BTreeSet::new();
    let mut dangling = Vec::new();
    for path in &files {
        let Ok(text) = std::fs::read_to_string(root().join(path)) else { continue };
        for (i, line) in text.lines().enumerate() {
            if path == THEORY && heading_section(line).is_some() {
                continue;
            }
            for n in citations(line) {
                cited += 1;
                citing_files.insert(path.split('/').next().unwrap().to_owned());
                if !sections.contains(&n) {
                    dangling.push(format!("{path}:{}: §{n}", i + 1));
                }
            }
        }
    }
    // The scan must have seen the code's citations, or it proves nothing.
    for top in ["README.md", "crates", "src", "tests", "docs"] {
        assert!(citing_files.contains(top), "no § citation found under {top}: the scan missed files ({files:?})");
    }
    assert!(cited > 100, "only {cited} § citations found");
    assert!(
        dangling.is_empty(),
        "{} citation(s) name no section heading of docs/theory.md:\n{}",
        dangling.len(),
        dangling.join("\n")
    );
}

#[test]
fn nothing_points_outside_the_repository_for_the_theory() {
    // Built at run time so that this file does not match itself.
    let outside = [["..", "/shared"].concat(), ["shared", "/docs"].concat()];
    let old_name = ["THEORY", ".md"].concat();
    let mut offending = Vec::new();
    for path in tracked_files() {
        let Ok(bytes) = std::fs::read(root().join(&path)) else { continue };
        let text = String::from_utf8_lossy(&bytes);
        for (i, line) in text.lines().enumerate() {
            for needle in &outside {
                if line.contains(needle.as_str()) {
                    offending.push(format!("{path}:{}: mentions {needle}", i + 1));
                }
            }
            if line.contains(&old_name) {
                offending.push(format!("{path}:{}: names {old_name} (the theory is {THEORY})", i + 1));
            }
        }
    }
    assert!(
        offending.is_empty(),
        "{} line(s) point outside docs/theory.md:\n{}",
        offending.len(),
        offending.join("\n")
    );
}
