//! The module structure of `src/` that docs/architecture.md describes, checked on the source:
//!
//! - **no import circles**: the graph whose nodes are the files of `src/` (one module each) and
//!   whose edges are the paths one file names in another (`use crate::…`, `super::…`,
//!   `self::…`, a child module's name, and `smithwalk::…` in `main.rs`) has no cycle;
//! - **the layer order**: setup < engine < io < analysis < exports < commands < `main.rs`; a
//!   file imports only from its own layer or a lower one; `atomic` serves every layer and imports
//!   none; nothing imports the crate root's re-exports (`crate::Config`), which would hide the
//!   layer an item comes from.
//!
//! Paths inside comments and string literals are ignored; paths in test modules count like any
//! other (a test helper in a parent module that a child imports is a circle too).
//!
//! The checker itself is tested on planted sources: a circle between two files, a circle
//! through a parent module and its child, and an upward import must each be reported, naming
//! the offending import (`the_check_reports_planted_circles_and_upward_imports`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The layers from bottom to top; a module's layer is that of its first path segment.
const LAYERS: [&str; 7] = ["setup", "engine", "io", "analysis", "exports", "commands", "main"];

/// An import of one module by another: where it is written and the path as written.
#[derive(Clone, Debug)]
struct Import {
    line: usize,
    path: String,
}

/// The import graph of a set of source files: per importing module, per imported module, the
/// first import that names it.
type Graph = BTreeMap<String, BTreeMap<String, Import>>;

/// The module path of a file of `src/` (`engine/detector/mod.rs` -> `engine::detector`);
/// `lib.rs` is the crate root `crate`, `main.rs` the binary `main`.
fn module_of(relative: &str) -> String {
    let trimmed = relative.trim_end_matches(".rs").trim_end_matches("/mod");
    match trimmed {
        "lib" => "crate".to_string(),
        other => other.replace('/', "::"),
    }
}

/// `source` with comments and the contents of string and character literals blanked (newlines
/// kept, so that line numbers stay).
fn strip(source: &str) -> String {
    let c: Vec<char> = source.chars().collect();
    let mut out = String::with_capacity(source.len());
    let blank = |ch: char| if ch == '\n' { '\n' } else { ' ' };
    let mut i = 0;
    while i < c.len() {
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(c[i]));
                    i += 1;
                }
            }
        } else if c[i] == 'r'
            && (i == 0 || !(c[i - 1].is_alphanumeric() || c[i - 1] == '_'))
            && matches!(c.get(i + 1), Some('"' | '#'))
        {
            // A raw string r"…" or r#"…"#: its end is the quote followed by as many hashes.
            let hashes = c[i + 1..].iter().take_while(|&&ch| ch == '#').count();
            if c.get(i + 1 + hashes) != Some(&'"') {
                out.push(c[i]);
                i += 1;
                continue;
            }
            let end: String = std::iter::once('"').chain(std::iter::repeat_n('#', hashes)).collect();
            let body_start = i + 2 + hashes;
            let rest: String = c[body_start..].iter().collect();
            let len = rest.find(&end).map_or(rest.chars().count(), |b| rest[..b].chars().count());
            out.push_str("r\"");
            out.extend(c[body_start..body_start + len].iter().map(|&ch| blank(ch)));
            out.push('"');
            i = body_start + len + end.chars().count();
        } else if c[i] == '"' {
            out.push('"');
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < c.len() {
                    out.push(blank(c[i]));
                    i += 1;
                }
            }
            out.push('"');
            i += 1;
        } else if c[i] == '\'' && (c.get(i + 2) == Some(&'\'') || c.get(i + 1) == Some(&'\\')) {
            // A character literal ('x', '\n', '\''); a lifetime ('a) has no closing quote.
            let close = (i + 2..c.len()).find(|&j| c[j] == '\'' && (c[j - 1] != '\\' || j == i + 2)).unwrap_or(i + 2);
            out.extend(std::iter::repeat_n(' ', close + 1 - i));
            i = close + 1;
        } else {
            out.push(c[i]);
            i += 1;
        }
    }
    out
}

/// A token of a path: an identifier, `::`, a brace or a comma, with its line.
#[derive(Clone, Debug, PartialEq)]
enum Token {
    Ident(String),
    Colons,
    Open,
    Close,
    Comma,
    Star,
    Other,
}

fn tokens(code: &str) -> Vec<(Token, usize)> {
    let c: Vec<char> = code.chars().collect();
    let (mut out, mut line, mut i) = (Vec::new(), 1, 0);
    while i < c.len() {
        let ch = c[i];
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if ch.is_alphabetic() || ch == '_' {
            let start = i;
            while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                i += 1;
            }
            out.push((Token::Ident(c[start..i].iter().collect()), line));
        } else if ch == ':' && c.get(i + 1) == Some(&':') {
            out.push((Token::Colons, line));
            i += 2;
        } else {
            out.push((
                match ch {
                    '{' => Token::Open,
                    '}' => Token::Close,
                    ',' => Token::Comma,
                    '*' => Token::Star,
                    _ => Token::Other,
                },
                line,
            ));
            i += 1;
        }
    }
    out
}

/// The paths of a `use` tree or an expression path starting at token `i` (an identifier that
/// does not follow `::`), each as its segments; a group `{a, b::c}` gives one path per leaf, and
/// `self` in a group names the prefix. Returns the paths and the index after them.
fn paths_at(t: &[(Token, usize)], mut i: usize) -> (Vec<Vec<String>>, usize) {
    let mut prefix = Vec::new();
    loop {
        match &t[i].0 {
            Token::Ident(name) => {
                prefix.push(name.clone());
                i += 1;
            }
            _ => return (vec![prefix], i),
        }
        if t.get(i).map(|x| &x.0) != Some(&Token::Colons) {
            return (vec![prefix], i);
        }
        i += 1;
        if t.get(i).map(|x| &x.0) == Some(&Token::Star) {
            prefix.push("*".to_string());
            return (vec![prefix], i + 1);
        }
        if t.get(i).map(|x| &x.0) == Some(&Token::Open) {
            i += 1;
            let mut out = Vec::new();
            while i < t.len() && t[i].0 != Token::Close {
                if t[i].0 == Token::Comma {
                    i += 1;
                    continue;
                }
                let (inner, next) = paths_at(t, i);
                for p in inner {
                    let mut full = prefix.clone();
                    full.extend(p.into_iter().filter(|s| s != "self"));
                    out.push(full);
                }
                i = if next == i { i + 1 } else { next };
            }
            return (out, i + 1);
        }
    }
}

/// The import graph of `files` (paths relative to `src/`, with their sources).
fn graph(files: &BTreeMap<String, String>) -> Graph {
    let modules: BTreeSet<String> = files.keys().map(|f| module_of(f)).collect();
    let mut graph = Graph::new();
    for (file, source) in files {
        let own = module_of(file);
        let base: Vec<String> =
            if own == "crate" || own == "main" { Vec::new() } else { own.split("::").map(String::from).collect() };
        let t = tokens(&strip(source));
        // Inline modules (`mod tests { … }`) open at a brace depth; `super` in them starts there.
        let (mut depth, mut inline): (usize, Vec<(String, usize)>) = (0, Vec::new());
        let mut i = 0;
        while i < t.len() {
            match &t[i].0 {
                Token::Open => {
                    depth += 1;
                    i += 1;
                    continue;
                }
                Token::Close => {
                    if inline.last().is_some_and(|(_, d)| *d == depth) {
                        inline.pop();
                    }
                    depth = depth.saturating_sub(1);
                    i += 1;
                    continue;
                }
                Token::Ident(m) if m == "mod" => {
                    if let (Some((Token::Ident(name), _)), Some((Token::Open, _))) = (t.get(i + 1), t.get(i + 2)) {
                        inline.push((name.clone(), depth + 1));
                    }
                    i += 1;
                    continue;
                }
                // A path after `::` is part of one already read; one after `in` is a visibility
                // (`pub(in crate::x)`), not an import.
                Token::Ident(_)
                    if i == 0 || !(t[i - 1].0 == Token::Colons || t[i - 1].0 == Token::Ident("in".into())) => {}
                _ => {
                    i += 1;
                    continue;
                }
            }
            let line = t[i].1;
            let (paths, next) = paths_at(&t, i);
            i = next.max(i + 1);
            let here: Vec<String> = base.iter().cloned().chain(inline.iter().map(|(n, _)| n.clone())).collect();
            for path in paths {
                if path.len() < 2 {
                    continue;
                }
                let mut resolved = here.clone();
                let rest: &[String] = match path[0].as_str() {
                    "crate" => {
                        resolved.clear();
                        &path[1..]
                    }
                    "smithwalk" if own == "main" => {
                        resolved.clear();
                        &path[1..]
                    }
                    "self" => &path[1..],
                    "super" => {
                        let supers = path.iter().take_while(|s| *s == "super").count();
                        resolved.truncate(resolved.len().saturating_sub(supers));
                        &path[supers..]
                    }
                    // A child module named without `self::` (uniform paths).
                    first
                        if modules.contains(
                            &here.iter().chain([&first.to_string()]).cloned().collect::<Vec<_>>().join("::"),
                        ) =>
                    {
                        &path[..]
                    }
                    _ => continue,
                };
                resolved.extend(rest.iter().cloned());
                // The imported file: the longest prefix of the path that is a module of src/.
                let target = (0..=resolved.len())
                    .rev()
                    .map(|n| if n == 0 { "crate".to_string() } else { resolved[..n].join("::") })
                    .find(|m| modules.contains(m))
                    .unwrap_or_else(|| "crate".to_string());
                if target == own {
                    continue;
                }
                graph.entry(own.clone()).or_default().entry(target).or_insert(Import { line, path: path.join("::") });
            }
        }
    }
    graph
}

/// The layer of a module: its index in [`LAYERS`], or `None` for `atomic` (below every layer)
/// and the crate root.
fn layer(module: &str) -> Option<usize> {
    let first = module.split("::").next().unwrap_or(module);
    LAYERS.iter().position(|l| *l == first)
}

/// How an import reads in a failure message.
fn describe(files: &BTreeMap<String, String>, from: &str, to: &str, import: &Import) -> String {
    let file = files.keys().find(|f| module_of(f) == from).map_or(from.to_string(), |f| format!("src/{f}"));
    format!("{file}:{} imports `{}` (module {to})", import.line, import.path)
}

/// Every circle of the import graph (each strongly connected set of more than one module), as
/// the imports along one cycle through it.
fn circles(files: &BTreeMap<String, String>, graph: &Graph) -> Vec<(BTreeSet<String>, Vec<String>)> {
    let reach = |from: &str| {
        let mut seen = BTreeSet::from([from.to_string()]);
        let mut stack = vec![from.to_string()];
        while let Some(m) = stack.pop() {
            for next in graph.get(&m).into_iter().flat_map(|e| e.keys()) {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for start in graph.keys() {
        if done.contains(start) {
            continue;
        }
        let forward = reach(start);
        let component: BTreeSet<String> =
            forward.iter().filter(|m| reach(m).contains(start.as_str())).cloned().collect();
        done.extend(component.iter().cloned());
        if component.len() < 2 {
            continue;
        }
        // One cycle: breadth-first from `start` back to it inside the component.
        let mut parent: BTreeMap<String, String> = BTreeMap::new();
        let mut queue = std::collections::VecDeque::from([start.clone()]);
        let mut last = None;
        while let Some(m) = queue.pop_front() {
            for next in graph.get(&m).into_iter().flat_map(|e| e.keys()).filter(|n| component.contains(*n)) {
                if next == start {
                    last = Some(m.clone());
                    queue.clear();
                    break;
                }
                if !parent.contains_key(next) {
                    parent.insert(next.clone(), m.clone());
                    queue.push_back(next.clone());
                }
            }
        }
        let mut cycle = vec![start.clone()];
        let mut m = last.expect("a strongly connected component has a cycle");
        while m != *start {
            cycle.push(m.clone());
            m = parent[&m].clone();
        }
        cycle.push(start.clone());
        cycle.reverse();
        let edges = cycle.windows(2).map(|w| describe(files, &w[0], &w[1], &graph[&w[0]][&w[1]])).collect();
        out.push((component, edges));
    }
    out
}

/// The failures of the check on `files`: circles and imports against the layer order, each
/// naming the offending import.
fn check(files: &BTreeMap<String, String>) -> Vec<String> {
    let graph = graph(files);
    let mut failures = Vec::new();
    for (component, edges) in circles(files, &graph) {
        failures.push(format!(
            "import circle between {}:\n    {}",
            component.iter().cloned().collect::<Vec<_>>().join(", "),
            edges.join("\n    ")
        ));
    }
    for (from, edges) in &graph {
        for (to, import) in edges {
            let why = if from == "crate" {
                None
            } else if to == "crate" {
                Some("the crate root's re-exports are for users: import the item from its module".to_string())
            } else {
                match (layer(from), layer(to)) {
                    (None, _) => Some(format!("`{from}` serves every layer and imports none of them")),
                    (Some(a), Some(b)) if b > a => {
                        Some(format!("layer `{}` is above layer `{}` ({})", LAYERS[b], LAYERS[a], LAYERS.join(" < ")))
                    }
                    _ => None,
                }
            };
            if let Some(why) = why {
                failures.push(format!("upward import: {}: {why}", describe(files, from, to, import)));
            }
        }
    }
    failures
}

/// Every `.rs` file under `dir`, keyed by its path relative to `root` (with `/`).
fn sources(root: &Path, dir: &Path, out: &mut BTreeMap<String, String>) {
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(root, &path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let relative = path.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/");
            out.insert(relative, std::fs::read_to_string(&path).unwrap());
        }
    }
}

/// `src/` keeps the layer order of docs/architecture.md and has no import circle.
#[test]
fn src_has_no_import_circles_and_keeps_the_layer_order() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = BTreeMap::new();
    sources(&src, &src, &mut files);
    assert!(files.len() > 40 && files.contains_key("engine/detector/mod.rs"), "src/ not found: {files:?}");
    let graph = graph(&files);
    // The graph is read: main uses the commands, which use every layer below.
    assert!(graph["main"].contains_key("commands::run") && graph["commands::run"].contains_key("engine::checkpoint"));
    let failures = check(&files);
    assert!(failures.is_empty(), "docs/architecture.md, \"Rules the code keeps\":\n{}", failures.join("\n"));
}

/// The check on planted sources: each planted fault is reported with the file, line and path
/// of the import that makes it, and a clean tree passes.
#[test]
fn the_check_reports_planted_circles_and_upward_imports() {
    let tree = |extra: &[(&str, &str)]| {
        let mut files: BTreeMap<String, String> = [
            ("lib.rs", "pub mod engine;\npub mod io;\npub use engine::run::Walk;\n"),
            ("engine/mod.rs", "pub mod run;\npub mod tally;\n"),
            ("engine/run.rs", "use crate::engine::tally::Tally; // crate::io::x in a comment\n"),
            ("engine/tally.rs", "pub struct Tally;\nconst S: &str = \"crate::io::Out\";\n"),
            ("io/mod.rs", "use crate::engine::{run::Walk, tally::{self, Tally}};\n"),
            ("atomic.rs", "pub fn write() {}\n"),
        ]
        .into_iter()
        .map(|(f, s)| (f.to_string(), s.to_string()))
        .collect();
        for (f, s) in extra {
            files.entry(f.to_string()).or_default().push_str(s);
        }
        check(&files)
    };
    assert_eq!(tree(&[]), Vec::<String>::new(), "comments and strings are not imports");

    let circle = tree(&[("engine/tally.rs", "fn f() { super::run::go(); }\n")]);
    assert_eq!(circle.len(), 1, "{circle:?}");
    assert!(
        circle[0].contains("engine::run, engine::tally")
            && circle[0].contains("src/engine/tally.rs:3 imports `super::run::go` (module engine::run)")
            && circle[0].contains("src/engine/run.rs:1 imports `crate::engine::tally::Tally`"),
        "{}",
        circle[0]
    );

    let parent = tree(&[
        ("engine/mod.rs", "use self::run::Walk;\npub struct Shared;\n"),
        ("engine/run.rs", "use super::Shared;\n"),
    ]);
    assert!(parent.iter().any(|f| f.contains("import circle between engine, engine::run")), "{parent:?}");

    let upward = tree(&[
        ("engine/run.rs", "use crate::io::Out;\n"),
        ("atomic.rs", "mod tests { use super::super::engine::run::Walk; }\n"),
    ]);
    assert!(
        upward.iter().any(|f| f
            .contains("src/engine/run.rs:2 imports `crate::io::Out` (module io): layer `io` is above layer `engine`")),
        "{upward:?}"
    );
    assert!(
        upward.iter().any(|f| f.contains("src/atomic.rs:2 imports `super::super::engine::run::Walk`")
            && f.contains("`atomic` serves every layer")),
        "{upward:?}"
    );

    let root = tree(&[("io/mod.rs", "fn f() -> crate::Walk { todo!() }\n")]);
    assert!(root.iter().any(|f| f.contains("imports `crate::Walk` (module crate)")), "{root:?}");
}
