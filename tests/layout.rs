//! The codebase's layout rules, checked on every test run (issue 53):
//!
//! * **No module import circle in any crate.** Every crate's module tree is read from its
//!   sources (`mod` declarations, with `syn`); every `use` and every path that starts with
//!   `crate`, `super` or `self` is resolved to the module that defines the item (through the
//!   `use` declarations of the module it names, so a re-export does not hide where an item
//!   lives). A reference from module `a::x` into `a::y`'s subtree is an edge `x -> y` between
//!   the siblings `x` and `y` of `a`; a module and its own descendants are one unit from
//!   outside and are not checked against each other. Among the siblings of every module, the
//!   edges must not close a circle. Test-only code (`#[cfg(test)]`, `cfg(any(test, ...))`)
//!   is left out: tests may reach anywhere.
//! * **One module layout:** `x.rs` beside `x/`, never `x/mod.rs`.
//! * **No orphan source file:** every `.rs` file under a crate's `src/` is a module of it
//!   (test modules included), so none is left out of the build without a word.
//! * **Files a few hundred lines long:** no source file has more than [`MAX_CODE_LINES`]
//!   lines of non-test code (not blank, not only a comment).
//! * **The real-time crates' graph:** the crates the real-time thread runs code of
//!   ([`REAL_TIME`]) depend, through `cargo tree`, on none of [`NEVER_REAL_TIME`]: not the
//!   planner, the language, fit, the machine file's parsing, serde or clap.

use proc_macro2::Span;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// Most lines of non-test code a source file may have.
const MAX_CODE_LINES: usize = 500;

/// The crates whose code runs in the real-time thread, and what they are built of.
const REAL_TIME: [&str; 5] = ["rt-loop", "nc-follow", "nc-geom", "drives", "machine"];

/// What none of them may depend on, directly or not.
const NEVER_REAL_TIME: [&str; 10] = [
    "nc-plan",
    "nc-lang",
    "nc-fit",
    "config",
    "dnurbs-tools",
    "serde",
    "serde_core",
    "serde_json",
    "toml",
    "clap",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tools/ has a parent")
        .to_path_buf()
}

/// The workspace's crates: (name, entry file). A package with a library and a binary has
/// two crates.
fn crates() -> Vec<(String, PathBuf)> {
    let text = std::fs::read_to_string(root().join("Cargo.toml")).expect("Cargo.toml");
    let ws: toml::Table = text.parse().expect("the workspace manifest parses");
    let members = ws["workspace"]["members"].as_array().expect("members");
    let mut out = Vec::new();
    for m in members {
        let dir = root().join(m.as_str().expect("a member is a path"));
        for entry in ["src/lib.rs", "src/main.rs"] {
            let file = dir.join(entry);
            if file.exists() {
                let name = format!("{}/{entry}", m.as_str().unwrap_or_default());
                out.push((name, file));
            }
        }
    }
    assert!(out.len() >= 10, "found only {out:?}");
    out
}

/// `#[cfg(...)]` that mentions `test`: code compiled for tests only.
fn test_only(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg") && {
            let text = a.meta.require_list().map(|l| l.tokens.to_string());
            text.is_ok_and(|t| {
                t.split(|c: char| !c.is_alphanumeric() && c != '_')
                    .any(|w| w == "test")
            })
        }
    })
}

fn item_attrs(item: &syn::Item) -> &[syn::Attribute] {
    match item {
        syn::Item::Const(i) => &i.attrs,
        syn::Item::Enum(i) => &i.attrs,
        syn::Item::ExternCrate(i) => &i.attrs,
        syn::Item::Fn(i) => &i.attrs,
        syn::Item::ForeignMod(i) => &i.attrs,
        syn::Item::Impl(i) => &i.attrs,
        syn::Item::Macro(i) => &i.attrs,
        syn::Item::Mod(i) => &i.attrs,
        syn::Item::Static(i) => &i.attrs,
        syn::Item::Struct(i) => &i.attrs,
        syn::Item::Trait(i) => &i.attrs,
        syn::Item::TraitAlias(i) => &i.attrs,
        syn::Item::Type(i) => &i.attrs,
        syn::Item::Union(i) => &i.attrs,
        syn::Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

/// A module of a crate.
#[derive(Default)]
struct Module {
    file: PathBuf,
    /// Paths (absolute within the crate where they start with crate/super/self, resolved
    /// below) this module refers to, with the line of each.
    refs: Vec<(Vec<String>, usize)>,
    /// Names brought in by `use`: name -> the path it stands for (raw, as written).
    uses: BTreeMap<String, Vec<String>>,
}

/// Everything found in one crate.
#[derive(Default)]
struct Tree {
    modules: BTreeMap<Vec<String>, Module>,
    /// Per file: its lines of non-test code.
    code_lines: BTreeMap<PathBuf, usize>,
    /// Files laid out as `x/mod.rs`.
    mod_rs: Vec<PathBuf>,
}

/// Collects references from a module's items (not descending into inline modules, which
/// are modules of their own, nor into test-only items).
struct Refs<'m> {
    module: &'m mut Module,
}

impl Refs<'_> {
    fn flatten(&mut self, tree: &syn::UseTree, prefix: &mut Vec<String>, line: usize) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.flatten(&p.tree, prefix, line);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                let name = n.ident.to_string();
                let mut full = prefix.clone();
                let local = if name == "self" {
                    prefix.last().cloned().unwrap_or_default()
                } else {
                    full.push(name.clone());
                    name
                };
                self.module.uses.insert(local, full.clone());
                self.module.refs.push((full, line));
            }
            syn::UseTree::Rename(r) => {
                let mut full = prefix.clone();
                if r.ident != "self" {
                    full.push(r.ident.to_string());
                }
                self.module.uses.insert(r.rename.to_string(), full.clone());
                self.module.refs.push((full, line));
            }
            syn::UseTree::Glob(_) => self.module.refs.push((prefix.clone(), line)),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.flatten(t, prefix, line);
                }
            }
        }
    }
}

impl<'ast> Visit<'ast> for Refs<'_> {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        if test_only(item_attrs(item)) || matches!(item, syn::Item::Mod(_)) {
            return;
        }
        syn::visit::visit_item(self, item);
    }

    fn visit_impl_item(&mut self, item: &'ast syn::ImplItem) {
        let attrs = match item {
            syn::ImplItem::Fn(f) => &f.attrs,
            syn::ImplItem::Const(c) => &c.attrs,
            _ => return syn::visit::visit_impl_item(self, item),
        };
        if !test_only(attrs) {
            syn::visit::visit_impl_item(self, item);
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let line = u.use_token.span.start().line;
        self.flatten(&u.tree, &mut Vec::new(), line);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segs: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        if segs.len() >= 2 && p.leading_colon.is_none() {
            let line = p.segments[0].ident.span().start().line;
            self.module.refs.push((segs, line));
        }
        syn::visit::visit_path(self, p);
    }
}

/// Lines of non-test code in `src`: not blank, not only a comment, outside the given
/// test-only line ranges.
fn code_lines(src: &str, test_ranges: &[(usize, usize)]) -> usize {
    src.lines()
        .enumerate()
        .filter(|(i, l)| {
            let n = i + 1;
            let t = l.trim();
            !t.is_empty()
                && !t.starts_with("//")
                && !test_ranges.iter().any(|&(a, b)| n >= a && n <= b)
        })
        .count()
}

fn span_lines(attrs: &[syn::Attribute], end: Span) -> (usize, usize) {
    let start = attrs
        .first()
        .map_or(end.start().line, |a| a.pound_token.span.start().line);
    (start, end.end().line)
}

/// Read module `path` from `file` (its items), and its submodules.
fn read_module(tree: &mut Tree, path: Vec<String>, file: &Path, items: &[syn::Item], mod_rs: bool) {
    let mut module = Module {
        file: file.to_path_buf(),
        ..Module::default()
    };
    let mut refs = Refs {
        module: &mut module,
    };
    for item in items {
        refs.visit_item(item);
    }
    tree.modules.insert(path.clone(), module);
    for item in items {
        let syn::Item::Mod(m) = item else { continue };
        if test_only(&m.attrs) {
            continue;
        }
        let mut sub = path.clone();
        sub.push(m.ident.to_string());
        match &m.content {
            Some((_, inner)) => read_module(tree, sub, file, inner, mod_rs),
            None => {
                let dir = if mod_rs {
                    file.parent().expect("a file's dir").to_path_buf()
                } else {
                    file.with_extension("")
                };
                let flat = dir.join(format!("{}.rs", m.ident));
                let nested = dir.join(m.ident.to_string()).join("mod.rs");
                let (f, is_mod_rs) = if flat.exists() {
                    (flat, false)
                } else if nested.exists() {
                    tree.mod_rs.push(nested.clone());
                    (nested, true)
                } else {
                    panic!("{}: mod {} has no file", file.display(), m.ident)
                };
                read_file(tree, sub, &f, is_mod_rs);
            }
        }
    }
}

fn read_file(tree: &mut Tree, path: Vec<String>, file: &Path, mod_rs: bool) {
    let src = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let ast = syn::parse_file(&src).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    // Test-only items, and inline modules (counted in their own right below).
    let mut tests = Vec::new();
    collect_test_ranges(&ast.items, &mut tests);
    tree.code_lines
        .insert(file.to_path_buf(), code_lines(&src, &tests));
    read_module(tree, path, file, &ast.items, mod_rs);
}

fn collect_test_ranges(items: &[syn::Item], out: &mut Vec<(usize, usize)>) {
    for item in items {
        let attrs = item_attrs(item);
        if test_only(attrs) {
            let end = match item {
                syn::Item::Mod(m) => m
                    .content
                    .as_ref()
                    .map_or(m.semi.map_or(m.ident.span(), |s| s.span), |(b, _)| {
                        b.span.close()
                    }),
                syn::Item::Fn(f) => f.block.brace_token.span.close(),
                syn::Item::Impl(i) => i.brace_token.span.close(),
                syn::Item::Use(u) => u.semi_token.span,
                syn::Item::Const(c) => c.semi_token.span,
                syn::Item::Struct(s) => s.ident.span(),
                _ => continue,
            };
            out.push(span_lines(attrs, end));
        } else if let syn::Item::Mod(m) = item {
            if let Some((_, inner)) = &m.content {
                collect_test_ranges(inner, out);
            }
        } else if let syn::Item::Impl(i) = item {
            for it in &i.items {
                if let syn::ImplItem::Fn(f) = it {
                    if test_only(&f.attrs) {
                        out.push(span_lines(&f.attrs, f.block.brace_token.span.close()));
                    }
                }
            }
        }
    }
}

fn read_crate(entry: &Path) -> Tree {
    let mut tree = Tree::default();
    read_file(&mut tree, Vec::new(), entry, true);
    tree
}

/// The module a path written in module `at` refers to: the longest prefix that is a module,
/// followed through that module's `use` of the next name (at most `depth` times).
fn resolve(tree: &Tree, at: &[String], path: &[String], depth: usize) -> Option<Vec<String>> {
    let mut abs: Vec<String> = match path.first().map(String::as_str) {
        Some("crate") => Vec::new(),
        Some("super") | Some("self") => at.to_vec(),
        // A path from a child module (2018's uniform paths: `use window::Planner`).
        Some(first) if tree.modules.contains_key(&child(at, first)) => at.to_vec(),
        _ => return None,
    };
    let mut rest = path;
    if rest.first().is_some_and(|s| s == "crate") {
        rest = &rest[1..];
    } else {
        while let Some(s) = rest.first() {
            match s.as_str() {
                "super" => {
                    abs.pop()?;
                }
                "self" => {}
                _ => break,
            }
            rest = &rest[1..];
        }
    }
    abs.extend(rest.iter().cloned());
    let mut k = abs.len();
    while k > 0 && !tree.modules.contains_key(&abs[..k]) {
        k -= 1;
    }
    let module = abs[..k].to_vec();
    if depth > 0 && k < abs.len() {
        if let Some(target) = tree.modules.get(&module).and_then(|m| m.uses.get(&abs[k])) {
            let mut next = target.clone();
            next.extend(abs[k + 1..].iter().cloned());
            if let Some(r) = resolve(tree, &module, &next, depth - 1) {
                return Some(r);
            }
        }
    }
    Some(module)
}

fn child(at: &[String], name: &str) -> Vec<String> {
    let mut c = at.to_vec();
    c.push(name.to_owned());
    c
}

/// Sibling edges (parent -> (from child -> to child -> an example)).
type Edges = BTreeMap<Vec<String>, BTreeMap<String, BTreeMap<String, String>>>;

fn edges(tree: &Tree) -> Edges {
    let mut out: Edges = BTreeMap::new();
    for (at, module) in &tree.modules {
        for (path, line) in &module.refs {
            let Some(to) = resolve(tree, at, path, 8) else {
                continue;
            };
            let k = at.iter().zip(&to).take_while(|(a, b)| a == b).count();
            if k == at.len() || k == to.len() {
                continue;
            }
            let example = format!("{}:{line}: {}", module.file.display(), path.join("::"));
            out.entry(at[..k].to_vec())
                .or_default()
                .entry(at[k].clone())
                .or_default()
                .entry(to[k].clone())
                .or_insert(example);
        }
    }
    out
}

/// The circles among one module's children: each strongly connected set of two or more,
/// with the edges inside it.
fn circles(graph: &BTreeMap<String, BTreeMap<String, String>>) -> Vec<Vec<String>> {
    let nodes: BTreeSet<&String> = graph
        .iter()
        .flat_map(|(a, bs)| std::iter::once(a).chain(bs.keys()))
        .collect();
    let reach = |from: &String| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(n) = stack.pop() {
            for next in graph.get(&n).into_iter().flat_map(|m| m.keys()) {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let mut out = Vec::new();
    let mut done = BTreeSet::new();
    for n in nodes {
        if done.contains(n) {
            continue;
        }
        let from_n = reach(n);
        let set: Vec<String> = from_n
            .iter()
            .filter(|m| reach(m).contains(n))
            .cloned()
            .collect();
        if !set.is_empty() {
            let mut all = set.clone();
            if !all.contains(n) {
                all.push(n.clone());
            }
            all.sort();
            done.extend(all.iter().cloned());
            let mut lines = Vec::new();
            for a in &all {
                for (b, ex) in graph.get(a).into_iter().flatten() {
                    if all.contains(b) {
                        lines.push(format!("{a} -> {b} ({ex})"));
                    }
                }
            }
            out.push(lines);
        }
    }
    out
}

#[test]
fn no_module_import_circle_in_any_crate() {
    let mut found = Vec::new();
    for (name, entry) in crates() {
        let tree = read_crate(&entry);
        for (parent, graph) in edges(&tree) {
            for circle in circles(&graph) {
                found.push(format!(
                    "{name}: in `{}`:\n    {}",
                    if parent.is_empty() {
                        "crate".to_owned()
                    } else {
                        parent.join("::")
                    },
                    circle.join("\n    ")
                ));
            }
        }
    }
    assert!(
        found.is_empty(),
        "module import circles:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_circle_check_finds_a_planted_circle() {
    // Two sibling modules that use each other, one through a re-export of its parent.
    let a: syn::File = syn::parse_quote! {
        mod x { use super::y::Y; pub struct X; }
        mod y { use crate::X2; pub struct Y; }
        pub use x::X as X2;
    };
    let mut tree = Tree::default();
    read_module(
        &mut tree,
        Vec::new(),
        Path::new("planted.rs"),
        &a.items,
        true,
    );
    let e = edges(&tree);
    let c = circles(&e[&Vec::new()]);
    assert_eq!(c.len(), 1, "{c:?}");
    assert!(c[0].iter().any(|l| l.starts_with("x -> y")), "{c:?}");
    assert!(c[0].iter().any(|l| l.starts_with("y -> x")), "{c:?}");
}

/// Every file `mod` declarations reach from `file` (test-only ones too), with `dir` the
/// folder its child modules' files are in.
fn reachable(file: &Path, dir: &Path, items: &[syn::Item], out: &mut BTreeSet<PathBuf>) {
    out.insert(file.to_path_buf());
    for item in items {
        let syn::Item::Mod(m) = item else { continue };
        let name = m.ident.to_string();
        match &m.content {
            Some((_, inner)) => reachable(file, &dir.join(&name), inner, out),
            None => {
                let flat = dir.join(format!("{name}.rs"));
                let (f, sub) = if flat.exists() {
                    (flat, dir.join(&name))
                } else {
                    (dir.join(&name).join("mod.rs"), dir.join(&name))
                };
                let src = std::fs::read_to_string(&f)
                    .unwrap_or_else(|e| panic!("{}: mod {name}: {e}", file.display()));
                let ast = syn::parse_file(&src).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
                reachable(&f, &sub, &ast.items, out);
            }
        }
    }
}

/// The `.rs` files under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = e.expect("a directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn every_source_file_is_a_module_of_its_crate() {
    let mut reached = BTreeSet::new();
    let mut dirs = BTreeSet::new();
    for (_, entry) in crates() {
        let src = std::fs::read_to_string(&entry).expect("the crate's entry");
        let ast = syn::parse_file(&src).expect("the crate's entry parses");
        let dir = entry.parent().expect("src/").to_path_buf();
        reachable(&entry, &dir, &ast.items, &mut reached);
        dirs.insert(dir);
    }
    let mut all = Vec::new();
    for d in &dirs {
        rust_files(d, &mut all);
    }
    let orphans: Vec<String> = all
        .iter()
        .filter(|f| !reached.contains(*f))
        .map(|f| f.display().to_string())
        .collect();
    assert!(all.len() > 100, "found only {} files", all.len());
    assert!(
        orphans.is_empty(),
        "source files no crate declares as a module (never built, never tested):\n{}",
        orphans.join("\n")
    );
}

#[test]
fn one_module_layout_and_files_of_a_few_hundred_lines() {
    let mut mod_rs = Vec::new();
    let mut long = Vec::new();
    for (_, entry) in crates() {
        let tree = read_crate(&entry);
        mod_rs.extend(tree.mod_rs.iter().map(|p| p.display().to_string()));
        for (file, n) in tree.code_lines {
            if n > MAX_CODE_LINES {
                long.push(format!("{}: {n} lines of non-test code", file.display()));
            }
        }
    }
    mod_rs.sort();
    mod_rs.dedup();
    long.sort();
    long.dedup();
    assert!(
        mod_rs.is_empty(),
        "modules laid out as x/mod.rs (the layout is x.rs beside x/):\n{}",
        mod_rs.join("\n")
    );
    assert!(
        long.is_empty(),
        "files over {MAX_CODE_LINES} lines of non-test code:\n{}",
        long.join("\n")
    );
}

#[test]
fn the_real_time_crates_depend_on_no_planner_interpreter_serde_or_clap() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    for krate in REAL_TIME {
        let out = std::process::Command::new(&cargo)
            .current_dir(root())
            .args([
                "tree",
                "--offline",
                "-e",
                "normal",
                "--prefix",
                "none",
                "-p",
                krate,
            ])
            .output()
            .expect("cargo tree runs");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && text.lines().count() > 1,
            "cargo tree -p {krate}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let deps: BTreeSet<&str> = text
            .lines()
            .filter_map(|l| l.split_whitespace().next())
            .collect();
        let bad: Vec<&&str> = NEVER_REAL_TIME
            .iter()
            .filter(|n| deps.contains(*n))
            .collect();
        assert!(bad.is_empty(), "{krate} depends on {bad:?}:\n{text}");
    }
}
