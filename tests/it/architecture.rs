//! The architecture the README promises, held by a test: no two modules of
//! a workspace crate import each other, directly or through others.
//!
//! Each crate's module tree is walked from its roots (`src/lib.rs`,
//! `src/main.rs`) along its `mod` declarations, so `foo.rs` and
//! `foo/mod.rs` are `foo`, `foo/bar.rs` is `foo::bar` and `#[path]` is
//! followed. Test-only code is left out: a `#[cfg(test)]` item (a `mod
//! tests;` file included) adds no edge, as tests may reach anywhere. Every
//! path a file writes — `use` trees with their groups, renames and globs,
//! and paths inline in code and in macro arguments (`crate::a::f()`,
//! `super::x`, `self::y`, `child::z`, `alias::w`) — is resolved to the
//! longest prefix that is a file's module, and makes an edge from the file
//! to that file, except to the file itself or to one of its ancestors (a
//! child is part of its parent: `use super::X` is no edge). The edges must
//! make no cycle.

use std::collections::{BTreeMap, BTreeSet, VecDeque};

use proc_macro2::{TokenStream, TokenTree};
use syn::visit::{self, Visit};
use syn::{Attribute, Item, ItemMod, ItemUse, UseTree};

/// Source files by path (`/`-separated, relative to the workspace root).
type Sources = BTreeMap<String, String>;

/// Each file and the files it imports.
type Graph = BTreeMap<String, BTreeSet<String>>;

/// A module path from the crate root (`[]` is the root).
type ModPath = Vec<String>;

/// One module of a crate's tree.
#[derive(Debug)]
struct Module {
    /// The file that holds it (its own, or its parent's for `mod m { … }`).
    file: String,
    /// Declared inline, `mod m { … }`, rather than in a file of its own.
    inline: bool,
    /// Under a `#[cfg(test)]`.
    test_only: bool,
    /// The names of the modules declared in it.
    children: BTreeSet<String>,
}

/// One crate's modules by path.
type Tree = BTreeMap<ModPath, Module>;

#[test]
fn no_module_imports_itself_through_others() {
    let root = crate::common::root();
    let mut graph = Graph::new();
    let mut unreached = Vec::new();
    for member in workspace_members(&read(&root.join("Cargo.toml"))) {
        let sources = crate_sources(&root, &member);
        let mut reached = BTreeSet::new();
        for crate_root in ["lib.rs", "main.rs"] {
            let file = format!("{member}/src/{crate_root}");
            if !sources.contains_key(&file) {
                continue;
            }
            let tree = module_tree(&sources, &file).unwrap_or_else(|e| panic!("{e}"));
            reached.extend(tree.values().map(|m| m.file.clone()));
            for (from, to) in import_graph(&sources, &tree).unwrap_or_else(|e| panic!("{e}")) {
                graph.entry(from).or_default().extend(to);
            }
        }
        unreached.extend(sources.keys().filter(|f| !reached.contains(*f)).cloned());
    }
    // A file no `mod` reaches would be a file this test never reads.
    assert!(
        unreached.is_empty(),
        "files no `mod` declares: {unreached:?}"
    );
    assert!(graph.len() > 100, "too few files read: {}", graph.len());
    let cycles = cycles(&graph);
    assert!(
        cycles.is_empty(),
        "modules that import each other (break each cycle: move what both need \
         into the lower module, or into a new small one):\n{}",
        cycles
            .iter()
            .map(|c| show(c))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// The workspace's members, from the `members = [...]` line of its manifest.
fn workspace_members(manifest: &str) -> Vec<String> {
    let line = manifest
        .lines()
        .find(|l| l.trim_start().starts_with("members"))
        .expect("a members line in Cargo.toml");
    let list = &line[line.find('[').expect("[") + 1..line.rfind(']').expect("]")];
    let members: Vec<String> = list
        .split(',')
        .map(|m| m.trim().trim_matches('"').to_owned())
        .filter(|m| !m.is_empty())
        .collect();
    assert!(members.len() >= 6, "workspace members: {members:?}");
    members
}

/// Every `.rs` file under `member/src/`, keyed by its path from the root.
fn crate_sources(root: &std::path::Path, member: &str) -> Sources {
    let mut sources = Sources::new();
    let mut dirs = vec![format!("{member}/src")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(root.join(&dir)).expect("read src/") {
            let entry = entry.expect("entry");
            let name = format!("{dir}/{}", entry.file_name().to_string_lossy());
            if entry.file_type().expect("file type").is_dir() {
                dirs.push(name);
            } else if name.ends_with(".rs") {
                sources.insert(name, read(&entry.path()));
            }
        }
    }
    sources
}

fn read(path: &std::path::Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn parse(sources: &Sources, file: &str) -> Result<syn::File, String> {
    let text = sources
        .get(file)
        .ok_or_else(|| format!("{file}: no such file"))?;
    syn::parse_file(text).map_err(|e| format!("{file}: {e}"))
}

/// The crate's modules, from the root file along its `mod` declarations.
fn module_tree(sources: &Sources, root: &str) -> Result<Tree, String> {
    let mut tree = Tree::new();
    tree.insert(
        vec![],
        Module {
            file: root.to_owned(),
            inline: false,
            test_only: false,
            children: BTreeSet::new(),
        },
    );
    let items = parse(sources, root)?.items;
    let at = Place {
        module: vec![],
        file: root.to_owned(),
        dir: dir_of(root),
        inline: false,
    };
    declare(sources, &items, &at, false, &mut tree)?;
    Ok(tree)
}

/// Where a list of items is: its module, its file, and the folder its
/// `mod m;` files are found in.
struct Place {
    module: ModPath,
    file: String,
    dir: String,
    inline: bool,
}

/// Adds the modules `items` declare (and theirs, recursively) to `tree`.
fn declare(
    sources: &Sources,
    items: &[Item],
    at: &Place,
    test_only: bool,
    tree: &mut Tree,
) -> Result<(), String> {
    for item in items {
        let Item::Mod(m) = item else { continue };
        let name = m.ident.to_string();
        let test_only = test_only || is_cfg_test(&m.attrs);
        let mut module = at.module.clone();
        module.push(name.clone());
        tree.get_mut(&at.module)
            .expect("parent")
            .children
            .insert(name.clone());
        let module_at = |place: &Place| Module {
            file: place.file.clone(),
            inline: place.inline,
            test_only,
            children: BTreeSet::new(),
        };
        match &m.content {
            Some((_, items)) => {
                let dir = format!("{}/{name}", at.dir);
                let place = Place {
                    module: module.clone(),
                    file: at.file.clone(),
                    dir,
                    inline: true,
                };
                tree.insert(module, module_at(&place));
                declare(sources, items, &place, test_only, tree)?;
            }
            None => {
                let file = match path_attr(&m.attrs) {
                    // Beside the declaring file, or in the inline module's folder.
                    Some(p) if at.inline => format!("{}/{p}", at.dir),
                    Some(p) => format!("{}/{p}", dir_of(&at.file)),
                    None => [
                        format!("{}/{name}.rs", at.dir),
                        format!("{}/{name}/mod.rs", at.dir),
                    ]
                    .into_iter()
                    .find(|f| sources.contains_key(f))
                    .ok_or_else(|| format!("{}: no file for `mod {name};`", at.file))?,
                };
                let dir = match file.strip_suffix("/mod.rs") {
                    Some(d) => d.to_owned(),
                    None => file.trim_end_matches(".rs").to_owned(),
                };
                let items = parse(sources, &file)?.items;
                let place = Place {
                    module: module.clone(),
                    file,
                    dir,
                    inline: false,
                };
                tree.insert(module, module_at(&place));
                declare(sources, &items, &place, test_only, tree)?;
            }
        }
    }
    Ok(())
}

fn dir_of(file: &str) -> String {
    file.rsplit_once('/').map_or("", |(d, _)| d).to_owned()
}

/// `#[cfg(test)]` exactly (`cfg(any(test, …))` is code outside tests too).
fn is_cfg_test(attrs: &[Attribute]) -> bool {
    attrs.iter().any(|a| match &a.meta {
        syn::Meta::List(l) => l.path.is_ident("cfg") && l.tokens.to_string() == "test",
        _ => false,
    })
}

/// The file named by `#[path = "…"]`.
fn path_attr(attrs: &[Attribute]) -> Option<String> {
    attrs.iter().find_map(|a| match &a.meta {
        syn::Meta::NameValue(nv) if nv.path.is_ident("path") => match &nv.value {
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) => Some(s.value()),
            _ => None,
        },
        _ => None,
    })
}

/// Each file of the crate (outside tests) and the files it imports.
fn import_graph(sources: &Sources, tree: &Tree) -> Result<Graph, String> {
    let mut graph = Graph::new();
    for (path, module) in tree {
        if module.inline || module.test_only {
            continue;
        }
        let file = parse(sources, &module.file)?;
        let mut paths = Paths {
            tree,
            module: path.clone(),
            aliases: vec![],
            found: vec![],
        };
        paths.items(&file.items);
        let to = graph.entry(module.file.clone()).or_default();
        for target in paths.found {
            // Not to itself, nor to an ancestor (whose part it is).
            if let Some(t) = file_of(tree, &target)
                && !path.starts_with(t)
            {
                to.insert(tree[t].file.clone());
            }
        }
    }
    Ok(graph)
}

/// The file module `path` is in: the longest of its prefixes that is a
/// module with a file of its own (none for a path into no module).
fn file_of<'t>(tree: &'t Tree, path: &[String]) -> Option<&'t [String]> {
    (0..=path.len())
        .rev()
        .map(|n| &path[..n])
        .find(|p| tree.get(*p).is_some_and(|m| !m.inline))
        .map(|p| tree.get_key_value(p).expect("key").0.as_slice())
}

/// Collects the crate paths one file writes, resolved to module paths.
struct Paths<'t> {
    tree: &'t Tree,
    /// The module being read (deeper than the file's within `mod m { … }`).
    module: ModPath,
    /// Per enclosing module, the names its `use` items bind to modules.
    aliases: Vec<BTreeMap<String, ModPath>>,
    found: Vec<ModPath>,
}

impl Paths<'_> {
    /// A module's items: its `use` items first bind their names, then every
    /// path is read.
    fn items(&mut self, items: &[Item]) {
        let mut aliases = BTreeMap::new();
        for item in items {
            if let Item::Use(u) = item
                && !is_cfg_test(&u.attrs)
            {
                for (path, name) in use_leaves(&u.tree) {
                    if let (Some(name), Some(m)) = (name, self.resolve(&path, true))
                        && self.tree.contains_key(&m)
                    {
                        aliases.insert(name, m);
                    }
                }
            }
        }
        self.aliases.push(aliases);
        for item in items {
            self.visit_item(item);
        }
        self.aliases.pop();
    }

    /// A path as written, to the module path it names (with what follows),
    /// or `None` if it is not into this crate.
    fn resolve(&self, path: &[String], in_use: bool) -> Option<ModPath> {
        let (first, rest) = path.split_first()?;
        let mut module = self.module.clone();
        match first.as_str() {
            "crate" => return Some(rest.to_vec()),
            "self" => {}
            "super" => {
                module.pop()?;
                let supers = rest.iter().take_while(|s| *s == "super").count();
                for _ in 0..supers {
                    module.pop()?;
                }
                module.extend_from_slice(&rest[supers..]);
                return Some(module);
            }
            // A bare name is a module only as a path's first segment.
            _ if rest.is_empty() && !in_use => return None,
            _ if self
                .tree
                .get(&module)
                .is_some_and(|m| m.children.contains(first)) =>
            {
                module.push(first.clone());
            }
            _ => {
                let alias = self.aliases.last().and_then(|a| a.get(first))?;
                module = alias.clone();
            }
        }
        module.extend_from_slice(rest);
        Some(module)
    }

    fn found(&mut self, path: Vec<String>, in_use: bool) {
        if let Some(m) = self.resolve(&path, in_use) {
            self.found.push(m);
        }
    }
}

impl<'ast> Visit<'ast> for Paths<'_> {
    fn visit_item(&mut self, item: &'ast Item) {
        let attrs = match item {
            Item::Const(i) => &i.attrs,
            Item::Enum(i) => &i.attrs,
            Item::Fn(i) => &i.attrs,
            Item::Impl(i) => &i.attrs,
            Item::Macro(i) => &i.attrs,
            Item::Mod(i) => &i.attrs,
            Item::Static(i) => &i.attrs,
            Item::Struct(i) => &i.attrs,
            Item::Trait(i) => &i.attrs,
            Item::Type(i) => &i.attrs,
            Item::Use(i) => &i.attrs,
            _ => return visit::visit_item(self, item),
        };
        if !is_cfg_test(attrs) {
            visit::visit_item(self, item);
        }
    }

    fn visit_item_mod(&mut self, m: &'ast ItemMod) {
        // A `mod m;` file is read on its own; an inline one here, as `m`.
        if let Some((_, items)) = &m.content {
            self.module.push(m.ident.to_string());
            self.items(items);
            self.module.pop();
        }
    }

    fn visit_item_use(&mut self, u: &'ast ItemUse) {
        if u.leading_colon.is_none() {
            for (path, _) in use_leaves(&u.tree) {
                self.found(path, true);
            }
        }
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        if p.leading_colon.is_none() {
            self.found(
                p.segments.iter().map(|s| s.ident.to_string()).collect(),
                false,
            );
        }
        visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        for path in token_paths(m.tokens.clone()) {
            self.found(path, false);
        }
        visit::visit_macro(self, m);
    }
}

/// A `use` tree's leaves: each full path, and the name it binds (none for
/// a glob). `a::{self, b as c, d::*}` is `a` as `a`, `a::b` as `c`, `a::d`.
fn use_leaves(tree: &UseTree) -> Vec<(Vec<String>, Option<String>)> {
    fn walk(
        tree: &UseTree,
        prefix: &mut Vec<String>,
        out: &mut Vec<(Vec<String>, Option<String>)>,
    ) {
        match tree {
            UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                walk(&p.tree, prefix, out);
                prefix.pop();
            }
            UseTree::Name(n) if n.ident == "self" => {
                out.push((prefix.clone(), prefix.last().cloned()));
            }
            UseTree::Name(n) => {
                let mut path = prefix.clone();
                path.push(n.ident.to_string());
                out.push((path, Some(n.ident.to_string())));
            }
            UseTree::Rename(r) => {
                let mut path = prefix.clone();
                if r.ident != "self" {
                    path.push(r.ident.to_string());
                }
                out.push((path, Some(r.rename.to_string())));
            }
            UseTree::Glob(_) => out.push((prefix.clone(), None)),
            UseTree::Group(g) => g.items.iter().for_each(|t| walk(t, prefix, out)),
        }
    }
    let mut out = vec![];
    walk(tree, &mut vec![], &mut out);
    out
}

/// The paths in a macro's arguments, `a::b::c` (not after `::`, so a
/// path's tail is not read as a path of its own).
fn token_paths(tokens: TokenStream) -> Vec<Vec<String>> {
    let mut out = vec![];
    let mut path: Vec<String> = vec![];
    let mut colons = 0; // `:` seen since the last identifier
    let mut after_colons = false; // the run began after a `::`
    for token in tokens {
        match token {
            TokenTree::Ident(i) if colons == 2 && !path.is_empty() => {
                path.push(i.to_string());
                colons = 0;
            }
            TokenTree::Ident(i) => {
                flush(&mut out, &mut path, after_colons);
                after_colons = colons == 2;
                path.push(i.to_string());
                colons = 0;
            }
            TokenTree::Punct(p) if p.as_char() == ':' && colons < 2 => colons += 1,
            TokenTree::Group(g) => {
                flush(&mut out, &mut path, after_colons);
                after_colons = false;
                colons = 0;
                out.extend(token_paths(g.stream()));
            }
            _ => {
                flush(&mut out, &mut path, after_colons);
                after_colons = false;
                colons = 0;
            }
        }
    }
    flush(&mut out, &mut path, after_colons);
    out
}

/// Keeps a path read from tokens unless it began after a `::`.
fn flush(out: &mut Vec<Vec<String>>, path: &mut Vec<String>, after_colons: bool) {
    if !path.is_empty() && !after_colons {
        out.push(std::mem::take(path));
    }
    path.clear();
}

/// Every cycle through the graph's edges: for each edge `a -> b`, the
/// shortest way back from `b` to `a`; each cycle once, as its files from
/// the least round to it again.
fn cycles(graph: &Graph) -> Vec<Vec<String>> {
    let mut found = BTreeSet::new();
    for (a, targets) in graph {
        for b in targets {
            if let Some(back) = shortest_path(graph, b, a) {
                let mut cycle = vec![a.clone()];
                cycle.extend(back);
                cycle.pop();
                let least = (0..cycle.len())
                    .min_by_key(|&i| &cycle[i])
                    .expect("nonempty");
                cycle.rotate_left(least);
                cycle.push(cycle[0].clone());
                found.insert(cycle);
            }
        }
    }
    found.into_iter().collect()
}

/// The shortest path from `from` to `to`, both included.
fn shortest_path(graph: &Graph, from: &str, to: &str) -> Option<Vec<String>> {
    let mut came_from: BTreeMap<&str, &str> = BTreeMap::new();
    let mut queue = VecDeque::from([from]);
    while let Some(at) = queue.pop_front() {
        if at == to {
            let mut path = vec![to.to_owned()];
            let mut at = to;
            while at != from {
                at = came_from[at];
                path.push(at.to_owned());
            }
            path.reverse();
            return Some(path);
        }
        for next in graph.get(at).into_iter().flatten() {
            if next != from && !came_from.contains_key(next.as_str()) {
                came_from.insert(next, at);
                queue.push_back(next);
            }
        }
    }
    None
}

fn show(cycle: &[String]) -> String {
    cycle.join(" -> ")
}

#[cfg(test)]
mod synthetic {
    use super::*;

    fn graph_of(files: &[(&str, &str)]) -> Graph {
        let sources: Sources = files
            .iter()
            .map(|(f, s)| (f.to_string(), s.to_string()))
            .collect();
        let tree = module_tree(&sources, "src/lib.rs").expect("tree");
        import_graph(&sources, &tree).expect("graph")
    }

    fn edges(graph: &Graph) -> Vec<String> {
        graph
            .iter()
            .flat_map(|(a, bs)| bs.iter().map(move |b| format!("{a} -> {b}")))
            .collect()
    }

    #[test]
    fn a_cycle_of_two_files_is_reported() {
        let graph = graph_of(&[
            ("src/lib.rs", "pub mod a; pub mod b;"),
            (
                "src/a.rs",
                "use crate::{b::{self, B}, a::A as Same}; pub struct A(b::B);",
            ),
            (
                "src/b.rs",
                "pub struct B; fn f() { let _ = format!(\"{:?}\", super::a::A(B)); }",
            ),
        ]);
        assert_eq!(
            cycles(&graph).iter().map(|c| show(c)).collect::<Vec<_>>(),
            ["src/a.rs -> src/b.rs -> src/a.rs"]
        );
    }

    #[test]
    fn a_cycle_through_an_alias_and_a_folder_is_reported() {
        let graph = graph_of(&[
            ("src/lib.rs", "mod a; mod b;"),
            ("src/a/mod.rs", "mod c; use c::C;"),
            (
                "src/a/c.rs",
                "use crate::b; fn f() -> b::B { todo!() } pub struct C;",
            ),
            (
                "src/b.rs",
                "use crate::a; pub struct B; fn g() { let _ = a::c::C; }",
            ),
        ]);
        assert_eq!(
            cycles(&graph).iter().map(|c| show(c)).collect::<Vec<_>>(),
            [
                "src/a/c.rs -> src/b.rs -> src/a/c.rs",
                "src/a/c.rs -> src/b.rs -> src/a/mod.rs -> src/a/c.rs"
            ]
        );
    }

    #[test]
    fn a_child_using_its_ancestors_is_no_edge_and_tests_add_none() {
        let graph = graph_of(&[
            ("src/lib.rs", "mod a; mod b; pub struct Root; pub use a::A;"),
            (
                "src/a.rs",
                "pub struct A(crate::Root); mod inner { use super::super::b::B; }",
            ),
            (
                "src/b.rs",
                "pub struct B(super::Root); #[cfg(test)] mod tests { use crate::a::A; }",
            ),
        ]);
        assert_eq!(
            edges(&graph),
            ["src/a.rs -> src/b.rs", "src/lib.rs -> src/a.rs"]
        );
        assert!(cycles(&graph).is_empty());
    }
}
