//! The house rules of ARCHITECTURE.md, checked on the source itself (issue 39): no import circle
//! between sibling modules anywhere in `src/` (the library and the CLI) nor between the page's ES
//! modules in `www/js/`, the core layers import only the layers the table lets them, and no file
//! in `src/` is over [`MAX_LINES`] lines.
//!
//! The import graph is read from the paths the code names (`crate::…`, `super::…`, `self::…`,
//! with `{…}` groups expanded), comments left out: a `use` and a path written in place are the
//! same dependency. An edge `a::x → b::y` between two modules is projected onto the children of
//! their common parent (`a → b`), so a circle through any depth shows up where the modules meet.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The line cap of a file in `src/` (issue 39: "no file in `src/` over 700 lines").
const MAX_LINES: usize = 700;

/// The core layers in the order of ARCHITECTURE.md's table: each may import only the layers
/// before it (`mtl` only the shared measurement maths: see [`MTL_MAY_IMPORT`]).
const CORE_ORDER: [&str; 12] = [
    "math", "error", "scenario", "measure", "localize", "channel", "track", "formats", "mtl",
    "plan", "study", "present",
];

/// What `mtl` may import ("`mtl` is separate from the single-target tracking stack").
const MTL_MAY_IMPORT: [&str; 4] = ["math", "error", "scenario", "measure"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file under `dir` with extension `ext`, sorted.
fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == ext) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A module path: `src/study/part/set.rs` → `[study, part, set]`; `mod.rs`, `lib.rs` and
/// `main.rs` name their folder. The CLI's modules start with `bin/scatterloc`.
fn module_of(file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(root().join("src")).unwrap();
    let mut parts: Vec<String> = rel
        .with_extension("")
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// `text` without its comments (`//` to the end of a line, `/* … */`) and string literals'
/// contents, so a path in a doc comment or a message is not an import.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0usize;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if b[i] == b'"' && (i == 0 || b[i - 1] != b'\'') {
            // A plain string (raw strings and escapes: `\"` does not end it).
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else {
            let c = text[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// The paths a use tree starting at `s` names, `{…}` groups expanded: `a::{b, c::d}` →
/// `[a::b, a::c::d]`. Returns the paths and the bytes read.
fn expand(s: &str) -> (Vec<Vec<String>>, usize) {
    let b = s.as_bytes();
    let mut prefix: Vec<String> = Vec::new();
    let mut i = 0;
    loop {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        if i < b.len() && b[i] == b'{' {
            i += 1;
            let mut paths = Vec::new();
            loop {
                while i < b.len() && (b[i].is_ascii_whitespace() || b[i] == b',') {
                    i += 1;
                }
                if i >= b.len() || b[i] == b'}' {
                    i += 1;
                    break;
                }
                let (inner, n) = expand(&s[i..]);
                i += n.max(1);
                for p in inner {
                    paths.push(prefix.iter().cloned().chain(p).collect());
                }
            }
            return (paths, i);
        }
        let start = i;
        while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
            i += 1;
        }
        if i == start {
            return (vec![prefix], i);
        }
        prefix.push(s[start..i].to_string());
        if s[i..].starts_with("::") {
            i += 2;
        } else {
            return (vec![prefix], i);
        }
    }
}

/// The module paths file `file` (module `me`) names through `crate::`, `super::` and `self::`.
fn named_paths(code: &str, me: &[String], crate_root: &[String]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let b = code.as_bytes();
    for kw in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(kw) {
            let at = from + k;
            from = at + kw.len();
            let boundary = at == 0 || !(b[at - 1].is_ascii_alphanumeric() || b[at - 1] == b'_');
            if !boundary || (kw == "self::" && at > 0 && b[at - 1] == b'$') {
                continue;
            }
            // `super::super::x`: count the chain.
            let mut base: Vec<String> = match kw {
                "crate::" => crate_root.to_vec(),
                "self::" => me.to_vec(),
                _ => me[..me.len().saturating_sub(1)].to_vec(),
            };
            let mut rest = &code[from..];
            while kw == "super::" && rest.starts_with("super::") {
                base.pop();
                rest = &rest["super::".len()..];
            }
            // `a/b.rs` and `a/b/mod.rs` are the same module `a::b`: `super` is `a` either way.
            for p in expand(rest).0 {
                out.push(base.iter().cloned().chain(p).collect());
            }
        }
    }
    out
}

/// The strongly connected groups (more than one node) of `graph` (Tarjan).
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on: BTreeSet<String>,
        out: Vec<Vec<String>>,
    }
    fn visit(t: &mut T, v: &str) {
        let n = t.index.len();
        t.index.insert(v.into(), n);
        t.low.insert(v.into(), n);
        t.stack.push(v.into());
        t.on.insert(v.into());
        let next: Vec<String> = t.g.get(v).into_iter().flatten().cloned().collect();
        for w in next {
            if !t.index.contains_key(&w) {
                visit(t, &w);
                let lw = t.low[&w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if t.on.contains(&w) {
                let iw = t.index[&w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut group = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(&w);
                let done = w == v;
                group.push(w);
                if done {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                t.out.push(group);
            }
        }
    }
    let mut t = T {
        g: graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    let nodes: Vec<String> = graph.keys().cloned().collect();
    for v in nodes {
        if !t.index.contains_key(&v) {
            visit(&mut t, &v);
        }
    }
    t.out
}

/// The import edges between modules of `src/`, each resolved to the longest existing module.
fn rust_edges() -> Vec<(Vec<String>, Vec<String>)> {
    let src = root().join("src");
    let all = files(&src, "rs");
    let modules: BTreeSet<Vec<String>> = all.iter().map(|f| module_of(f)).collect();
    let mut edges = Vec::new();
    for f in &all {
        let me = module_of(f);
        let crate_root: Vec<String> = if me.starts_with(&["bin".into(), "scatterloc".into()]) {
            vec!["bin".into(), "scatterloc".into()]
        } else {
            Vec::new()
        };
        let code = code_only(&std::fs::read_to_string(f).unwrap());
        for mut p in named_paths(&code, &me, &crate_root) {
            while !p.is_empty() && !modules.contains(&p) {
                p.pop();
            }
            if p != me {
                edges.push((me.clone(), p));
            }
        }
    }
    edges
}

/// `edges` projected onto the children of each pair's common parent.
fn sibling_graph(edges: &[(Vec<String>, Vec<String>)]) -> BTreeMap<String, BTreeSet<String>> {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, b) in edges {
        let common = a.iter().zip(b).take_while(|(x, y)| x == y).count();
        if common < a.len() && common < b.len() {
            g.entry(a[..=common].join("::"))
                .or_default()
                .insert(b[..=common].join("::"));
        }
    }
    g
}

#[test]
fn use_tree_groups_expand() {
    let (p, _) = expand("a::{b, c::{d, e}}, x");
    let p: Vec<String> = p.iter().map(|p| p.join("::")).collect();
    assert_eq!(p, ["a::b", "a::c::d", "a::c::e"]);
    assert_eq!(
        code_only("x // crate::y\nz \"crate::w\" /* super::v */"),
        "x \nz \"\" "
    );
    // The circle finder on a known graph: a → b → c → a and d → a.
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (a, b) in [("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")] {
        g.entry(a.into()).or_default().insert(b.into());
    }
    assert_eq!(circles(&g), vec![vec!["a", "b", "c"]]);
}

#[test]
fn no_import_circle_in_src() {
    let edges = rust_edges();
    // The check sees the imports: the CLI's commands import the shared flag table, the study
    // layer imports the tracker.
    assert!(edges
        .iter()
        .any(|(a, b)| a.join("::") == "study::track" && b.first().is_some_and(|s| s == "track")));
    let found = circles(&sibling_graph(&edges));
    let explain: Vec<String> = found
        .iter()
        .map(|group| {
            let mut lines = vec![group.join(" ⇄ ")];
            for (a, b) in &edges {
                let (ja, jb) = (a.join("::"), b.join("::"));
                let inside = |m: &str| {
                    group
                        .iter()
                        .any(|g| m == g || m.starts_with(&format!("{g}::")))
                };
                let top = |m: &str| {
                    group
                        .iter()
                        .find(|g| m == *g || m.starts_with(&format!("{g}::")))
                        .cloned()
                };
                if inside(&ja) && inside(&jb) && top(&ja) != top(&jb) {
                    lines.push(format!("    {ja} → {jb}"));
                }
            }
            lines.join("\n")
        })
        .collect();
    assert!(found.is_empty(), "import circles:\n{}", explain.join("\n"));
}

#[test]
fn core_layers_import_only_the_layers_above_them() {
    let mut bad = Vec::new();
    for (a, b) in rust_edges() {
        let (Some(la), Some(lb)) = (a.first(), b.first()) else {
            continue;
        };
        if la == lb {
            continue;
        }
        let Some(ia) = CORE_ORDER.iter().position(|l| l == la) else {
            continue;
        };
        let allowed = match CORE_ORDER.iter().position(|l| l == lb) {
            None => false, // the core never imports an edge (`edge`, `bin`)
            Some(ib) if la == "mtl" => MTL_MAY_IMPORT.contains(&lb.as_str()) && ib < ia,
            Some(ib) => ib < ia,
        };
        if !allowed {
            bad.push(format!("{} → {}", a.join("::"), b.join("::")));
        }
    }
    bad.sort();
    bad.dedup();
    assert!(
        bad.is_empty(),
        "imports against ARCHITECTURE.md's layer table:\n{}",
        bad.join("\n")
    );
}

#[test]
fn no_file_in_src_over_the_line_cap() {
    let mut long = Vec::new();
    for f in files(&root().join("src"), "rs") {
        let n = std::fs::read_to_string(&f).unwrap().lines().count();
        if n > MAX_LINES {
            long.push(format!(
                "{} ({n} lines)",
                f.strip_prefix(root()).unwrap().display()
            ));
        }
    }
    assert!(
        long.is_empty(),
        "files over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
}

#[test]
fn no_import_circle_between_the_page_modules() {
    let dir = root().join("www/js");
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let js = files(&dir, "js");
    assert!(js.len() > 10, "the page's modules are read: {}", js.len());
    for f in &js {
        let name = f.strip_prefix(&dir).unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(f).unwrap();
        // `import … from './x.js'`, `export … from './x.js'` and `import('./x.js')`.
        for (i, _) in text.match_indices("'./") {
            let rest = &text[i + 3..];
            let Some(end) = rest.find('\'') else { continue };
            let target = &rest[..end];
            let before = text[..i].trim_end();
            let is_import = before.ends_with("from")
                || before.ends_with("import(")
                || before.ends_with("import");
            if is_import && target.ends_with(".js") && target != name {
                g.entry(name.clone())
                    .or_default()
                    .insert(target.to_string());
            }
        }
    }
    assert!(
        g.values().map(BTreeSet::len).sum::<usize>() > 20,
        "the imports are read"
    );
    let found = circles(&g);
    assert!(
        found.is_empty(),
        "import circles between www/js modules: {found:?}"
    );
}
