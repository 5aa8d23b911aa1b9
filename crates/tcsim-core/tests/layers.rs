//! The module layout of `src`: the folders depend one way (`converter` ← `engine` ← `vehicle`) and
//! no module depends on itself through others (no import cycle). Dependencies are the `crate::…`
//! and `super::…` paths in the code of each file (comments and test modules left out).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `crate::a::b` of a file (`lib.rs` is `crate`, `a/mod.rs` is `crate::a`).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    std::iter::once("crate".to_string()).chain(parts).collect::<Vec<_>>().join("::")
}

/// The modules a file's code names, resolved to the longest known module path.
fn dependencies(module: &str, code: &str, modules: &BTreeSet<String>) -> BTreeSet<String> {
    let parent = module.rsplit_once("::").map_or("crate", |(p, _)| p).to_string();
    let mut deps = BTreeSet::new();
    let bytes: Vec<char> = code.chars().collect();
    let text: String = bytes.iter().collect();
    for start in ["crate::", "super::"] {
        for (i, _) in text.match_indices(start) {
            if i > 0 && (bytes[i - 1].is_alphanumeric() || bytes[i - 1] == '_') {
                continue;
            }
            let path: String =
                text[i..].chars().take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':').collect();
            let path = path.trim_end_matches(':');
            let path = match path.strip_prefix("super") {
                Some(rest) => format!("{parent}{rest}"),
                None => path.to_string(),
            };
            let parts: Vec<&str> = path.split("::").collect();
            if let Some(m) = (1..=parts.len()).rev().map(|k| parts[..k].join("::")).find(|m| modules.contains(m)) {
                if m != module {
                    deps.insert(m);
                }
            }
        }
    }
    deps
}

/// The `src` folder of a crate of the workspace (`tcsim-core`, `tcsim-fmu`, `tcsim-py`).
fn src_of(krate: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(krate).join("src")
}

fn graph_of(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let src = src.to_path_buf();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(&src, f)).collect();
    files
        .iter()
        .map(|f| {
            let text = fs::read_to_string(f).unwrap();
            let code: String = text
                .split("#[cfg(test)]")
                .next()
                .unwrap()
                .lines()
                .map(|l| l.split("//").next().unwrap())
                .collect::<Vec<_>>()
                .join("\n");
            let m = module_of(&src, f);
            let deps = dependencies(&m, &code, &modules);
            (m, deps)
        })
        .collect()
}

fn graph() -> BTreeMap<String, BTreeSet<String>> {
    graph_of(&src_of("tcsim-core"))
}

fn layer(module: &str) -> Option<usize> {
    ["converter", "engine", "vehicle"].iter().position(|f| module.split("::").nth(1) == Some(f))
}

#[test]
fn folders_depend_one_way() {
    for (m, deps) in graph() {
        for d in deps {
            if let (Some(a), Some(b)) = (layer(&m), layer(&d)) {
                assert!(b <= a, "{m} uses {d}, a higher folder");
            }
        }
    }
}

#[test]
fn no_module_cycle() {
    for krate in ["tcsim-core", "tcsim-fmu", "tcsim-py"] {
        assert_acyclic(&graph_of(&src_of(krate)));
    }
    let g = graph();
    assert!(g.contains_key("crate::engine::converter_events") && g.len() > 20);
    assert!(graph_of(&src_of("tcsim-fmu")).contains_key("crate::variables"));
}

/// Panics on an import cycle in a crate's module graph.
fn assert_acyclic(g: &BTreeMap<String, BTreeSet<String>>) {
    // a folder's header (`mod.rs`) holds shared constants for its children: a child naming its
    // parent is not a cycle
    let edges = |m: &str| -> Vec<String> {
        let parent = m.rsplit_once("::").map(|(p, _)| p.to_string());
        g[m].iter().filter(|d| Some((*d).clone()) != parent).cloned().collect()
    };
    fn visit(m: &str, edges: &dyn Fn(&str) -> Vec<String>, state: &mut BTreeMap<String, u8>, stack: &mut Vec<String>) {
        state.insert(m.to_string(), 1);
        stack.push(m.to_string());
        for d in edges(m) {
            match state.get(&d) {
                Some(1) => panic!("import cycle: {} -> {d}", stack.join(" -> ")),
                Some(_) => {}
                None => visit(&d, edges, state, stack),
            }
        }
        stack.pop();
        state.insert(m.to_string(), 2);
    }
    let mut state = BTreeMap::new();
    for m in g.keys() {
        if !state.contains_key(m) {
            visit(m, &edges, &mut state, &mut Vec::new());
        }
    }
}
