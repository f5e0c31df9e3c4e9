//! No import circle among the app's modules: a module that uses another
//! (`use crate::…`, `use super::…` or such a path in its code) must not be
//! used back by it, directly or through others, so each can be read and
//! changed on its own. A module's own parents and children do not count
//! (a child uses its parent's state; the parent declares the child). Test
//! modules at the end of a file (`#[cfg(test)] mod tests`) are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module path, `["desktop", "files"]`.
type Module = Vec<String>;

/// Each module of the files under `src` (a crate's `src` folder; `main.rs`
/// left out) and its text.
fn modules(src: &Path) -> Vec<(Module, String)> {
    let mut found = Vec::new();
    let mut folders = vec![src.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).expect("reads the folder") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                folders.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") || path.ends_with("main.rs") {
                continue;
            }
            let relative = path
                .strip_prefix(src)
                .expect("inside src")
                .with_extension("");
            let mut module: Module = relative
                .iter()
                .map(|part| part.to_string_lossy().into_owned())
                .collect();
            // A folder's module is named after the folder.
            if matches!(module.last().map(String::as_str), Some("mod" | "lib")) {
                module.pop();
            }
            let text = std::fs::read_to_string(&path).expect("reads the file");
            found.push((module, text));
        }
    }
    found
}

/// The code of a file without its comments and its test module at the end.
fn code(text: &str) -> String {
    let text = text
        .split("#[cfg(test)]\nmod tests")
        .next()
        .unwrap_or_default();
    text.lines()
        .map(|line| line.split("//").next().unwrap_or_default())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths that start at `at` in `code` (after `crate` or `super`),
/// with each `{a, b::c}` group spread out.
fn paths_at(code: &[u8], at: &mut usize) -> Vec<Vec<String>> {
    let mut prefix = Vec::new();
    loop {
        while code.get(*at).is_some_and(|c| c.is_ascii_whitespace()) {
            *at += 1;
        }
        if code.get(*at) == Some(&b'{') {
            *at += 1;
            let mut paths = Vec::new();
            loop {
                for path in paths_at(code, at) {
                    let mut full = prefix.clone();
                    full.extend(path);
                    paths.push(full);
                }
                while code.get(*at).is_some_and(|&c| c != b',' && c != b'}') {
                    *at += 1;
                }
                match code.get(*at) {
                    Some(b',') => *at += 1,
                    _ => {
                        *at += 1;
                        return paths;
                    }
                }
            }
        }
        let start = *at;
        while code
            .get(*at)
            .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
        {
            *at += 1;
        }
        if *at == start {
            return vec![prefix];
        }
        prefix.push(String::from_utf8_lossy(&code[start..*at]).into_owned());
        if code.get(*at..*at + 2) == Some(b"::") {
            *at += 2;
        } else {
            return vec![prefix];
        }
    }
}

/// Which modules each module uses, parents and children left out.
fn uses(files: &[(Module, String)]) -> BTreeMap<Module, BTreeSet<Module>> {
    let known: BTreeSet<&Module> = files.iter().map(|(m, _)| m).collect();
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (module, text) in files {
        let code = code(text);
        let bytes = code.as_bytes();
        let mut at = 0;
        while at < bytes.len() {
            let word_start = at == 0
                || !(bytes[at - 1].is_ascii_alphanumeric()
                    || bytes[at - 1] == b'_'
                    || bytes[at - 1] == b':');
            let starts = ["crate::", "super::"]
                .into_iter()
                .find(|s| word_start && bytes[at..].starts_with(s.as_bytes()));
            let Some(_) = starts else {
                at += 1;
                continue;
            };
            for path in paths_at(bytes, &mut at) {
                let mut here: Module = module.clone();
                let mut rest = path.as_slice();
                if rest.first().map(String::as_str) == Some("crate") {
                    here.clear();
                    rest = &rest[1..];
                }
                while rest.first().map(String::as_str) == Some("super") {
                    here.pop();
                    rest = &rest[1..];
                }
                here.extend(rest.iter().cloned());
                let target = (1..=here.len())
                    .rev()
                    .map(|k| here[..k].to_vec())
                    .find(|m| known.contains(m));
                if let Some(target) = target
                    && !target.starts_with(module)
                    && !module.starts_with(&target)
                {
                    edges.entry(module.clone()).or_default().insert(target);
                }
            }
        }
    }
    edges
}

/// The circles in `edges`: each group of modules that reach each other
/// (Tarjan's strongly connected components of more than one module).
fn circles(edges: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    struct Walk<'a> {
        edges: &'a BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<&'a Module, usize>,
        low: BTreeMap<&'a Module, usize>,
        stack: Vec<&'a Module>,
        found: Vec<Vec<Module>>,
    }
    fn visit<'a>(walk: &mut Walk<'a>, v: &'a Module) {
        let n = walk.index.len();
        walk.index.insert(v, n);
        walk.low.insert(v, n);
        walk.stack.push(v);
        for w in walk.edges.get(v).into_iter().flatten() {
            if !walk.index.contains_key(w) {
                visit(walk, w);
                let low = walk.low[v].min(walk.low[w]);
                walk.low.insert(v, low);
            } else if walk.stack.contains(&w) {
                let low = walk.low[v].min(walk.index[w]);
                walk.low.insert(v, low);
            }
        }
        if walk.low[v] == walk.index[v] {
            let mut group = Vec::new();
            while let Some(w) = walk.stack.pop() {
                group.push(w.clone());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                walk.found.push(group);
            }
        }
    }
    let mut walk = Walk {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        found: Vec::new(),
    };
    for v in edges.keys() {
        if !walk.index.contains_key(v) {
            visit(&mut walk, v);
        }
    }
    walk.found
}

fn module(path: &str) -> Module {
    path.split("::").map(str::to_string).collect()
}

#[test]
fn the_app_has_no_import_circle() {
    let files = modules(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    assert!(files.len() > 40, "the app's modules are found");
    let edges = uses(&files);
    assert!(
        edges[&module("desktop::command")].contains(&module("desktop::prompts")),
        "uses are found"
    );
    let found = circles(&edges);
    let shown: Vec<String> = found
        .iter()
        .map(|group| {
            group
                .iter()
                .map(|m| {
                    let used: Vec<String> = edges[m]
                        .iter()
                        .filter(|t| group.contains(t))
                        .map(|t| t.join("::"))
                        .collect();
                    format!("{} -> {}", m.join("::"), used.join(", "))
                })
                .collect::<Vec<_>>()
                .join("; ")
        })
        .collect();
    assert!(
        found.is_empty(),
        "import circles among the app's modules (move what both need into a module of its own): {shown:#?}"
    );
}

#[test]
fn a_circle_through_groups_and_super_paths_is_found_and_parents_do_not_count() {
    let file = |path: &str, text: &str| (module(path), text.to_string());
    let files = vec![
        file("desktop", "mod a; mod b; use a::X;"),
        file(
            "desktop::a",
            "use super::{AnthesisApp, b::{Y, Z}};\n// use crate::desktop::c;",
        ),
        file("desktop::b", "fn f() { crate::desktop::c::g(); }"),
        file("desktop::c", "use super::super::desktop::a::X;"),
        file("look", "pub fn h() {}"),
    ];
    let edges = uses(&files);
    assert_eq!(edges.get(&module("desktop")), None, "a child is not a use");
    assert_eq!(
        edges[&module("desktop::a")],
        BTreeSet::from([module("desktop::b")]),
        "the parent and the commented-out use do not count"
    );
    assert_eq!(
        circles(&edges),
        vec![vec![
            module("desktop::a"),
            module("desktop::b"),
            module("desktop::c")
        ]]
    );
    let mut broken = files;
    broken[3].1 = "use crate::look::h;".to_string();
    assert!(circles(&uses(&broken)).is_empty());
}
