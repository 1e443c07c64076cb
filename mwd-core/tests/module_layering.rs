//! The crate's modules form layers: no module imports, directly or through
//! others, a module that imports it back (as in adskalman-rs, the filter
//! machinery in `kalman` is a leaf; models and aiding sources sit above
//! it). Read from the source: every `crate::name` a module's code (not its
//! comments or tests) mentions is an edge from that top-level module.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

fn source_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Top-level modules declared in lib.rs.
fn top_level_modules() -> Vec<String> {
    let lib = fs::read_to_string(source_dir().join("lib.rs")).expect("lib.rs");
    lib.lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .map(|rest| rest.trim_end_matches(';').to_string())
        .collect()
}

/// The files of a top-level module: `name.rs` and everything under `name/`.
fn files_of(module: &str) -> Vec<PathBuf> {
    let mut files = Vec::new();
    let file = source_dir().join(format!("{module}.rs"));
    if file.exists() {
        files.push(file);
    }
    let mut dirs = vec![source_dir().join(module)];
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    files
}

/// The code of a file without comments and without its test module
/// (`tests.rs` and `*_tests.rs` files, and everything from a
/// `#[cfg(test)]` on).
fn code_of(path: &Path) -> String {
    let test_file = path
        .file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.ends_with("tests.rs"));
    if test_file {
        return String::new();
    }
    let text = fs::read_to_string(path).expect("source file");
    text.lines()
        .take_while(|l| l.trim() != "#[cfg(test)]")
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Edges module -> modules it names as `crate::name`.
fn dependencies(modules: &[String]) -> BTreeMap<String, BTreeSet<String>> {
    let mut graph = BTreeMap::new();
    for module in modules {
        let mut used = BTreeSet::new();
        for file in files_of(module) {
            let code = code_of(&file);
            for (at, _) in code.match_indices("crate::") {
                let rest = &code[at + "crate::".len()..];
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if modules.contains(&name) && &name != module {
                    used.insert(name);
                }
            }
            // `use crate::{a, b::c}` groups.
            for (at, _) in code.match_indices("crate::{") {
                let group = &code[at + "crate::{".len()..];
                let group = &group[..group.find('}').unwrap_or(group.len())];
                for item in group.split(',') {
                    let name = item.trim().split("::").next().unwrap_or("");
                    if modules.iter().any(|m| m == name) && name != module {
                        used.insert(name.to_string());
                    }
                }
            }
        }
        graph.insert(module.clone(), used);
    }
    graph
}

/// A cycle through the graph, if there is one.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(start) = path.iter().position(|n| n == node) {
            let mut cycle = path[start..].to_vec();
            cycle.push(node.to_string());
            return Some(cycle);
        }
        if done.contains(node) {
            return None;
        }
        path.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(cycle) = visit(next, graph, path, done) {
                return Some(cycle);
            }
        }
        path.pop();
        done.insert(node.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|start| visit(start, graph, &mut Vec::new(), &mut done))
}

#[test]
fn no_module_imports_itself_back() {
    let modules = top_level_modules();
    assert!(modules.len() >= 10, "modules found: {modules:?}");
    let graph = dependencies(&modules);
    // The reader finds the edges it must (else the test would pass on
    // nothing): the filter uses the earth model, the navigator the filter.
    assert!(graph["fine_alignment"].contains("earth"), "{graph:?}");
    assert!(graph["probe"].contains("fine_alignment"), "{graph:?}");
    if let Some(cycle) = find_cycle(&graph) {
        panic!("import circle: {}", cycle.join(" -> "));
    }
}

#[test]
fn the_filter_machinery_is_a_leaf() {
    let graph = dependencies(&top_level_modules());
    assert!(
        graph["kalman"].is_empty(),
        "kalman imports {:?}",
        graph["kalman"]
    );
}

#[test]
fn the_cycle_finder_finds_a_cycle() {
    let mut graph = BTreeMap::new();
    let edge = |a: &str| BTreeSet::from([a.to_string()]);
    graph.insert("a".to_string(), edge("b"));
    graph.insert("b".to_string(), edge("c"));
    graph.insert("c".to_string(), edge("a"));
    assert_eq!(find_cycle(&graph).map(|c| c.len()), Some(4));
    graph.insert("c".to_string(), BTreeSet::new());
    assert_eq!(find_cycle(&graph), None);
}
