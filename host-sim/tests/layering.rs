//! The workspace's shape, checked on its sources:
//!
//! * no file-level import cycle in any crate of the workspace: two files
//!   never import each other, directly or through others;
//! * host-sim's library stages in the data's way (`src/lib.rs` lists them):
//!   a stage's files import only their own stage and the stages before it.
//!
//! An import is a `crate::`, `super::` or `self::` path in code (comments
//! and strings aside), or a module file's use of one of its own child
//! modules by name. A `pub use` of a file's own descendants (a re-export)
//! and the `mod` declarations are not imports. `#[cfg(test)]` code is left
//! out: a test may build its data with any stage.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// host-sim's library stages, in the order the data meets them.
const STAGES: [&str; 9] = [
    "formats",
    "analysis",
    "sim",
    "replay",
    "alignment",
    "survey",
    "study",
    "paper",
    "dashboard",
];

fn workspace() -> PathBuf {
    let w = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    w.canonicalize().unwrap_or(w)
}

/// One source file of a crate's module tree.
struct SourceFile {
    path: PathBuf,
    /// Module path from the crate root (`["survey", "listing"]`).
    module: Vec<String>,
    /// Child modules declared in it, by name.
    children: BTreeSet<String>,
    /// The code's tokens, comments, strings and `#[cfg(test)]` items removed.
    tokens: Vec<String>,
}

/// Identifiers, `::` and single punctuation characters of Rust code, with
/// comments, string and character literals dropped.
fn tokens(src: &str) -> Vec<String> {
    let b: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == '/' && b.get(i + 1) == Some(&'/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && b.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if c == 'r' && (b.get(i + 1) == Some(&'#') || b.get(i + 1) == Some(&'"')) {
            // Raw string r#"..."#: skip to the quote followed by as many #.
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push("r".into());
                i += 1;
                continue;
            }
            j += 1;
            while j < b.len() {
                if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            i = j;
        } else if c == '"' {
            i += 1;
            while i < b.len() && b[i] != '"' {
                i += if b[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else if c == '\'' {
            // A character literal ('x', '\n', '\u{..}') or a lifetime ('a).
            if b.get(i + 1) == Some(&'\\') {
                i += 2;
                while i < b.len() && b[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if b.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
            }
        } else if c.is_alphanumeric() || c == '_' {
            let start = i;
            while i < b.len() && (b[i].is_alphanumeric() || b[i] == '_') {
                i += 1;
            }
            out.push(b[start..i].iter().collect());
        } else if c == ':' && b.get(i + 1) == Some(&':') {
            out.push("::".into());
            i += 2;
        } else {
            if !c.is_whitespace() {
                out.push(c.to_string());
            }
            i += 1;
        }
    }
    out
}

/// The end (exclusive) of the item starting at `i`: through its matching
/// `}` or its `;`, whichever comes first at depth 0.
fn item_end(t: &[String], mut i: usize) -> usize {
    let mut depth = 0i32;
    while i < t.len() {
        match t[i].as_str() {
            "{" => depth += 1,
            "}" => {
                depth -= 1;
                if depth == 0 {
                    return i + 1;
                }
            }
            ";" if depth == 0 => return i + 1,
            _ => {}
        }
        i += 1;
    }
    t.len()
}

/// `tokens` without the items marked `#[cfg(test)]`, and the names of the
/// `mod x;` declarations that are not test-only.
fn without_tests(t: Vec<String>) -> (Vec<String>, Vec<String>) {
    let mut keep = Vec::new();
    let mut mods = Vec::new();
    let mut i = 0;
    while i < t.len() {
        if t[i] == "#" && t.get(i + 1).is_some_and(|s| s == "[") {
            let close = (i..t.len()).find(|&k| t[k] == "]").unwrap_or(t.len() - 1);
            let attr: String = t[i + 2..close].concat();
            if attr == "cfg(test)" {
                i = item_end(&t, close + 1);
                continue;
            }
            keep.extend_from_slice(&t[i..=close]);
            i = close + 1;
            continue;
        }
        if t[i] == "mod" && t.get(i + 2).is_some_and(|s| s == ";") && (i == 0 || t[i - 1] != "::") {
            // `#[path = "x"]` just before: the attribute's string was
            // dropped with the other strings, so such a module is reported
            // by name and its file found by the caller.
            mods.push(t[i + 1].clone());
        }
        keep.push(t[i].clone());
        i += 1;
    }
    (keep, mods)
}

/// The `#[path = "..."]` of a module declaration, read from the raw text.
fn path_attribute(src: &str, module: &str) -> Option<String> {
    let needle = format!("mod {module};");
    let at = src.find(&needle)?;
    let before = &src[..at];
    let line_start = before.trim_end().rfind('\n').map_or(0, |p| p + 1);
    let attr_line = before[..line_start].trim_end().rsplit('\n').next()?;
    let attr_line = if before[line_start..].trim_start().starts_with("#[path") {
        &before[line_start..]
    } else {
        attr_line
    };
    let rest = attr_line.trim().strip_prefix("#[path = \"")?;
    Some(rest[..rest.find('"')?].to_string())
}

/// Every file of the module tree rooted at `root` (a crate's lib.rs or
/// main.rs), test-only modules left out.
fn module_tree(root: &Path) -> Vec<SourceFile> {
    let mut files = Vec::new();
    let mut queue = vec![(root.to_path_buf(), Vec::<String>::new(), true)];
    while let Some((path, module, owns_dir)) = queue.pop() {
        let src =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let (tokens, mods) = without_tests(tokens(&src));
        let dir = path.parent().unwrap().to_path_buf();
        let child_dir = if owns_dir {
            dir.clone()
        } else {
            dir.join(path.file_stem().unwrap())
        };
        let mut children = BTreeSet::new();
        for name in mods {
            let (file, owns) = match path_attribute(&src, &name) {
                Some(p) => (dir.join(p), false),
                None if child_dir.join(format!("{name}.rs")).exists() => {
                    (child_dir.join(format!("{name}.rs")), false)
                }
                None => (child_dir.join(&name).join("mod.rs"), true),
            };
            assert!(file.exists(), "{}: module {name}: no file", path.display());
            let mut m = module.clone();
            m.push(name.clone());
            children.insert(name);
            queue.push((file, m, owns));
        }
        files.push(SourceFile {
            path,
            module,
            children,
            tokens,
        });
    }
    files
}

/// Full module paths named in `t` from `i` on (`a::b::{c, d::e}` gives
/// `a::b::c` and `a::b::d::e`); returns them and the index after the path.
fn paths_at(t: &[String], mut i: usize, prefix: Vec<String>) -> (Vec<Vec<String>>, usize) {
    let mut path = prefix;
    while let Some(tok) = t.get(i) {
        if tok == "{" {
            let mut all = Vec::new();
            i += 1;
            while i < t.len() && t[i] != "}" {
                if t[i] == "," {
                    i += 1;
                    continue;
                }
                let (sub, next) = paths_at(t, i, path.clone());
                all.extend(sub);
                i = next.max(i + 1);
            }
            return (all, i + 1);
        }
        if tok.chars().all(|c| c.is_alphanumeric() || c == '_') {
            path.push(tok.clone());
            i += 1;
            if t.get(i).is_some_and(|s| s == "::") {
                i += 1;
                continue;
            }
        }
        break;
    }
    (vec![path], i)
}

/// File-level imports of every file of a module tree: index -> indices.
fn imports(files: &[SourceFile]) -> Vec<BTreeSet<usize>> {
    let by_module: BTreeMap<&[String], usize> = files
        .iter()
        .enumerate()
        .map(|(k, f)| (f.module.as_slice(), k))
        .collect();
    let file_of = |path: &[String]| -> Option<usize> {
        (0..=path.len())
            .rev()
            .find_map(|n| by_module.get(&path[..n]).copied())
    };
    files
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let t = &f.tokens;
            let mut out = BTreeSet::new();
            let mut reexport = false;
            // Inline modules (`mod x { ... }`) open around the tokens: their
            // names and the brace depth inside each.
            let mut inline: Vec<(String, usize)> = Vec::new();
            let mut depth = 0usize;
            let mut i = 0;
            while i < t.len() {
                let tok = t[i].as_str();
                match tok {
                    ";" => reexport = false,
                    "{" => {
                        depth += 1;
                        if i >= 2 && t[i - 2] == "mod" {
                            inline.push((t[i - 1].clone(), depth));
                        }
                    }
                    "}" => {
                        if inline.last().is_some_and(|(_, d)| *d == depth) {
                            inline.pop();
                        }
                        depth = depth.saturating_sub(1);
                    }
                    _ => {}
                }
                if tok == "pub" && t[i + 1..].iter().take(5).any(|s| s == "use") {
                    reexport = true;
                }
                let after_sep = i > 0 && t[i - 1] == "::";
                let starts = !after_sep
                    && t.get(i + 1).is_some_and(|s| s == "::")
                    && (matches!(tok, "crate" | "super" | "self") || f.children.contains(tok));
                if !starts {
                    i += 1;
                    continue;
                }
                let mut base = f.module.clone();
                base.extend(inline.iter().map(|(name, _)| name.clone()));
                let mut j = i;
                match tok {
                    "crate" => {
                        base.clear();
                        j += 2;
                    }
                    _ => {
                        while t.get(j).is_some_and(|s| s == "super" || s == "self") {
                            if t[j] == "super" {
                                base.pop();
                            }
                            j += 2;
                        }
                    }
                }
                let (paths, next) = paths_at(t, j, base);
                for p in paths {
                    let Some(target) = file_of(&p) else { continue };
                    let own_descendant = files[target].module.starts_with(&f.module);
                    if target != k && !(reexport && own_descendant) {
                        out.insert(target);
                    }
                }
                i = next.max(i + 1);
            }
            out
        })
        .collect()
}

/// A source file's path as a reader finds it: from the workspace's root.
fn shown(path: &Path) -> String {
    let w = workspace();
    path.strip_prefix(&w).unwrap_or(path).display().to_string()
}

/// The import cycles of a module tree, each as its files' paths.
fn cycles(files: &[SourceFile], edges: &[BTreeSet<usize>]) -> Vec<Vec<String>> {
    // Tarjan's strongly connected components, iteratively small enough to
    // recurse: a crate has at most a few hundred files.
    struct Tarjan<'a> {
        edges: &'a [BTreeSet<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        stack: Vec<usize>,
        on_stack: Vec<bool>,
        next: usize,
        found: Vec<Vec<usize>>,
    }
    impl Tarjan<'_> {
        fn visit(&mut self, v: usize) {
            self.index[v] = Some(self.next);
            self.low[v] = self.next;
            self.next += 1;
            self.stack.push(v);
            self.on_stack[v] = true;
            for &w in self.edges[v].iter() {
                match self.index[w] {
                    None => {
                        self.visit(w);
                        self.low[v] = self.low[v].min(self.low[w]);
                    }
                    Some(iw) if self.on_stack[w] => self.low[v] = self.low[v].min(iw),
                    Some(_) => {}
                }
            }
            if Some(self.low[v]) == self.index[v] {
                let mut component = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 {
                    self.found.push(component);
                }
            }
        }
    }
    let n = files.len();
    let mut t = Tarjan {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        stack: Vec::new(),
        on_stack: vec![false; n],
        next: 0,
        found: Vec::new(),
    };
    for v in 0..n {
        if t.index[v].is_none() {
            t.visit(v);
        }
    }
    t.found
        .into_iter()
        .map(|c| {
            let mut names: Vec<String> = c.into_iter().map(|k| shown(&files[k].path)).collect();
            names.sort();
            names
        })
        .collect()
}

/// Every crate root of the workspace (libraries and binaries).
fn crate_roots() -> Vec<PathBuf> {
    let w = workspace();
    let mut roots: Vec<PathBuf> = [
        "mwd-core/src/lib.rs",
        "hil-mock/src/lib.rs",
        "firmware/src/lib.rs",
        "host-sim/src/lib.rs",
        "host-sim/src/main.rs",
        "tests/src/lib.rs",
    ]
    .iter()
    .map(|p| w.join(p))
    .collect();
    let bins = w.join("firmware/src/bin");
    for entry in std::fs::read_dir(&bins).expect("firmware/src/bin") {
        let p = entry.expect("firmware/src/bin entry").path();
        if p.join("main.rs").exists() {
            roots.push(p.join("main.rs"));
        } else if p.extension().is_some_and(|e| e == "rs") {
            roots.push(p);
        }
    }
    roots
}

#[test]
fn no_file_of_the_workspace_imports_itself_through_others() {
    let mut all = Vec::new();
    for root in crate_roots() {
        let files = module_tree(&root);
        all.extend(cycles(&files, &imports(&files)));
    }
    assert!(
        all.is_empty(),
        "file-level import cycles:\n{}",
        all.iter()
            .map(|c| c.join(" <-> "))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn each_host_sim_stage_imports_only_earlier_stages() {
    let files = module_tree(&workspace().join("host-sim/src/lib.rs"));
    let edges = imports(&files);
    let stage = |f: &SourceFile| {
        f.module
            .first()
            .and_then(|s| STAGES.iter().position(|x| x == s))
    };
    let mut wrong = Vec::new();
    for (k, f) in files.iter().enumerate() {
        let Some(from) = stage(f) else { continue };
        for &t in &edges[k] {
            if let Some(to) = stage(&files[t]) {
                if to > from {
                    wrong.push(format!(
                        "{} ({}) imports {} ({})",
                        shown(&f.path),
                        STAGES[from],
                        shown(&files[t].path),
                        STAGES[to]
                    ));
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // Every stage is a folder of the library, in lib.rs in this order.
    let lib = std::fs::read_to_string(workspace().join("host-sim/src/lib.rs")).expect("lib.rs");
    let declared: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.trim().strip_prefix("pub mod "))
        .map(|l| l.trim_end_matches(';'))
        .collect();
    assert_eq!(
        declared, STAGES,
        "lib.rs declares the stages in their order"
    );
}

#[test]
fn the_checker_sees_the_imports_it_must_see() {
    // A parent and child importing each other, a re-export, a path inside a
    // string and a test-only import: only the first is a cycle.
    let dir = std::env::temp_dir().join(format!("layering-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::write(
        dir.join("lib.rs"),
        "pub mod a;\npub mod b;\nconst S: &str = \"crate::a::X\";\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("a/mod.rs"),
        "mod child;\npub use child::Y;\nuse crate::b::Z;\n#[cfg(test)]\nmod tests { use crate::b::W; }\n",
    )
    .unwrap();
    std::fs::write(dir.join("a/child.rs"), "pub struct Y;\n").unwrap();
    std::fs::write(
        dir.join("b.rs"),
        "use crate::a::{child::Y, X};\npub struct Z;\n",
    )
    .unwrap();
    let files = module_tree(&dir.join("lib.rs"));
    let edges = imports(&files);
    let idx = |end: &str| files.iter().position(|f| f.path.ends_with(end)).unwrap();
    let (lib, a, child, b) = (idx("lib.rs"), idx("a/mod.rs"), idx("child.rs"), idx("b.rs"));
    assert!(edges[lib].is_empty(), "a path in a string is no import");
    assert_eq!(
        edges[a],
        BTreeSet::from([b]),
        "the re-export is not an import"
    );
    assert!(edges[child].is_empty());
    assert_eq!(edges[b], BTreeSet::from([a, child]));
    assert_eq!(cycles(&files, &edges).len(), 1, "a/mod.rs <-> b.rs");
    std::fs::remove_dir_all(&dir).ok();
}
