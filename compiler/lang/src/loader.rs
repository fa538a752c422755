//! Loads a job file and everything it `use`s: standard-library modules
//! embedded in the binary (shown as `std/NAME.lens`) and other `.lens`
//! files by path relative to the file that uses them, never from outside
//! the project root (`sandbox` says which files may be read and how). File
//! access goes through the `FileSystem` trait so the compiler core stays
//! pure.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use lensc_grammar::ast::{self, Ident, ItemKind, Span, UseTarget};
use lensc_grammar::diagnostic::codes as syntax_codes;
use lensc_grammar::{Diagnostic, FileId};

use crate::codes;
pub use crate::sandbox::Root;
pub use crate::sandbox::plain_io_error;
use crate::sandbox::{self, ReadError};
use crate::source::SourceMap;
use lensc_grammar::suggest::did_you_mean;

/// The standard library: module name and its text.
pub const STDLIB: &[(&str, &str)] = &[
    ("machines", include_str!("../../../stdlib/machines.lens")),
    ("tools", include_str!("../../../stdlib/tools.lens")),
    (
        "strategies",
        include_str!("../../../stdlib/strategies.lens"),
    ),
    ("dialects", include_str!("../../../stdlib/dialects.lens")),
];

/// The module every file sees without a `use`: the controller dialects,
/// so a machine anywhere can say `dialect: fanuc_0i_lathe`. Its names come
/// after every other name in scope: a file's own `dialect` of the same name
/// wins.
pub const PRELUDE: &str = "dialects";

pub trait FileSystem {
    /// The text of the regular file `path` (resolved, as `canonical` gives
    /// it) beneath the project root `root`, bounded in size: opened
    /// through the root's directory handle, never by its full name.
    fn read(&self, root: &Root, path: &Path) -> Result<Vec<u8>, ReadError>;
    /// The path made absolute with its symlinks resolved: equal for two
    /// paths naming the same file, and what the project root is checked on.
    fn canonical(&self, path: &Path) -> PathBuf;
}

/// The real file system: regular files of one name and at most
/// `sandbox::MAX_FILE_BYTES`, read without blocking, beneath the root.
pub struct RealFs;

impl FileSystem for RealFs {
    fn read(&self, root: &Root, path: &Path) -> Result<Vec<u8>, ReadError> {
        root.read(path, sandbox::MAX_FILE_BYTES)
    }
    fn canonical(&self, path: &Path) -> PathBuf {
        sandbox::resolve(path)
    }
}

/// What one `use` brings into a file's scope.
#[derive(Clone, Debug)]
pub enum Import {
    /// Every top-level `let` and declaration of the file.
    All { file: FileId, span: Span },
    /// One named item of the file.
    One { file: FileId, name: Ident },
}

pub struct ParsedFile {
    pub id: FileId,
    /// Its syntax tree; a standard-library module's is parsed once in a
    /// process and shared by every load (`std_tree`).
    pub ast: Arc<ast::File>,
    pub imports: Vec<Import>,
}

/// The syntax tree of standard-library module `index` (of `STDLIB`),
/// parsed the first time a load in this process asks for it and shared
/// after: every check loads the prelude (the 20 KB of `dialects`), the
/// language server checks on every change, and the fuzzer checks
/// thousands of files a second, each of which parsed it again. A tree
/// does not depend on the file id it is loaded under (ids are carried by
/// diagnostics only) and the standard library parses without any
/// (`tests::the_standard_library_parses_clean_and_once`).
fn std_tree(index: usize) -> Arc<ast::File> {
    static TREES: [OnceLock<Arc<ast::File>>; STDLIB.len()] =
        [const { OnceLock::new() }; STDLIB.len()];
    let (_, text) = STDLIB[index];
    Arc::clone(TREES[index].get_or_init(|| Arc::new(lensc_grammar::parse(text, FileId(0)).0)))
}

pub struct Loaded {
    pub sources: SourceMap,
    /// Indexed by `FileId`; the first is the root file.
    pub files: Vec<ParsedFile>,
    pub diags: Vec<Diagnostic>,
    /// The project root every file was read beneath, kept open for the
    /// files a job names beside its `use`s (a `compensate` block's
    /// measurement), which are read under the same rules.
    pub root: Option<std::sync::Arc<Root>>,
}

impl Loaded {
    pub fn file(&self, id: FileId) -> &ParsedFile {
        &self.files[id.0 as usize]
    }

    /// FNV-1a 64 over every loaded source, in load order, each followed
    /// by a zero byte: the hash a program's header carries (`source PATH
    /// fnv1a64 …`), which `lensc verify` checks against the file.
    pub fn fnv1a64(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for (_, f) in self.sources.iter() {
            for b in f.text.bytes().chain(std::iter::once(0u8)) {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        }
        h
    }
}

/// Loads `file` (as the user named it) and the closure of its `use`s,
/// with the directory `file` is in as the project root.
pub fn load(fs: &dyn FileSystem, file: &Path) -> Result<Loaded, ReadError> {
    load_in(fs, file, None)
}

/// Loads `file` and the closure of its `use`s, none of which may resolve
/// outside `root` (`None`: the directory `file` is in). `file` itself must
/// lie inside a `root` given.
pub fn load_in(fs: &dyn FileSystem, file: &Path, root: Option<&Path>) -> Result<Loaded, ReadError> {
    let resolved = fs.canonical(file);
    let root = match root {
        Some(r) => fs.canonical(r),
        None => fs.canonical(directory_of(file)),
    };
    if !sandbox::inside(&resolved, &root) {
        return Err(ReadError::OutsideRoot { resolved, root });
    }
    let root = Root::open(root);
    let bytes = fs.read(&root, &resolved)?;
    Ok(load_bytes(fs, root, Key::Path(resolved), file, bytes))
}

/// Loads source text given directly (tests, benchmarks); `use` of a path
/// is resolved relative to the working directory, which is the root.
pub fn load_text(fs: &dyn FileSystem, name: &str, text: &[u8]) -> Loaded {
    load_bytes(
        fs,
        Root::open(fs.canonical(Path::new("."))),
        Key::Path(PathBuf::from(name)),
        Path::new(name),
        text.to_vec(),
    )
}

/// The directory a file is in (`.` for a bare file name).
fn directory_of(file: &Path) -> &Path {
    file.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

fn load_bytes(fs: &dyn FileSystem, root: Root, key: Key, path: &Path, bytes: Vec<u8>) -> Loaded {
    let mut l = Loader {
        fs,
        root,
        loaded: Loaded {
            sources: SourceMap::default(),
            files: Vec::new(),
            diags: Vec::new(),
            root: None,
        },
        keys: HashMap::new(),
        stack: Vec::new(),
        on_stack: HashMap::new(),
        refused_more: false,
    };
    l.add(
        key,
        path.display().to_string(),
        Some(path.to_path_buf()),
        bytes,
    );
    let mut loaded = l.loaded;
    loaded.root = Some(std::sync::Arc::new(l.root));
    loaded
}

#[derive(Clone, PartialEq, Eq, Hash)]
enum Key {
    Path(PathBuf),
    Std(String),
}

struct Loader<'f> {
    fs: &'f dyn FileSystem,
    /// The project root, opened once: no file outside it is read, and each
    /// file is opened through its handle.
    root: Root,
    loaded: Loaded,
    keys: HashMap<Key, FileId>,
    /// Files being loaded, outermost first, to detect import cycles.
    stack: Vec<(Key, FileId)>,
    /// Where each file being loaded is on `stack`: a cycle is found in
    /// constant time, so a chain of n `use`s loads in O(n).
    on_stack: HashMap<Key, usize>,
    /// Whether a `use` past `MAX_FILES` was refused (said once).
    refused_more: bool,
}

/// The most files one check loads (the standard library's included): a
/// project of more is refused (E0189) rather than loaded without bound,
/// and the depth of a chain of `use`s is bounded with it.
pub const MAX_FILES: usize = 1000;

impl Loader<'_> {
    fn add(&mut self, key: Key, name: String, path: Option<PathBuf>, bytes: Vec<u8>) -> FileId {
        let (text, utf8_error) = match String::from_utf8(bytes) {
            Ok(t) => (t, None),
            Err(e) => {
                let at = e.utf8_error().valid_up_to();
                (String::from_utf8_lossy(e.as_bytes()).into_owned(), Some(at))
            }
        };
        let id = self.loaded.sources.add(name, path.clone(), text);
        self.keys.insert(key.clone(), id);
        self.loaded.files.push(ParsedFile {
            id,
            ast: Arc::default(),
            imports: Vec::new(),
        });
        if let Some(at) = utf8_error {
            self.loaded.diags.push(
                Diagnostic::error(
                    syntax_codes::NOT_UTF8,
                    "this file is not valid UTF-8",
                    id,
                    Span::new(at, at + 3),
                )
                .with_label("the first byte that is not UTF-8")
                .with_help("save the file as UTF-8; units like µm and ° need it"),
            );
            return id;
        }
        let std_index = match &key {
            Key::Std(name) => STDLIB.iter().position(|(n, _)| n == name),
            Key::Path(_) => None,
        };
        let ast = match std_index {
            Some(i) => std_tree(i),
            None => {
                let (ast, mut diags) = lensc_grammar::parse(&self.loaded.sources.get(id).text, id);
                self.loaded.diags.append(&mut diags);
                Arc::new(ast)
            }
        };
        self.on_stack.insert(key.clone(), self.stack.len());
        self.stack.push((key.clone(), id));
        let mut imports = Vec::new();
        for item in &ast.items {
            if let ItemKind::Use(target) = &item.kind {
                self.resolve_use(id, path.as_deref(), target, item.span, &mut imports);
            }
        }
        if key != Key::Std(PRELUDE.to_string()) {
            imports.push(Import::All {
                file: self.std_module(PRELUDE),
                span: Span::new(0, 0),
            });
        }
        if let Some((k, _)) = self.stack.pop() {
            self.on_stack.remove(&k);
        }
        let slot = &mut self.loaded.files[id.0 as usize];
        slot.ast = ast;
        slot.imports = imports;
        id
    }

    /// The standard-library module `name`, loaded once.
    fn std_module(&mut self, name: &str) -> FileId {
        let key = Key::Std(name.to_string());
        if let Some(&f) = self.keys.get(&key) {
            return f;
        }
        let text = STDLIB
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, t)| *t)
            .expect("a standard-library module");
        self.add(
            key,
            format!("std/{name}.lens"),
            None,
            text.as_bytes().to_vec(),
        )
    }

    fn resolve_use(
        &mut self,
        from: FileId,
        from_path: Option<&Path>,
        target: &UseTarget,
        span: Span,
        imports: &mut Vec<Import>,
    ) {
        match target {
            UseTarget::Std(segs) => self.use_std(from, segs, span, imports),
            UseTarget::File { path, span: pspan } => {
                self.use_file(from, from_path, path, *pspan, span, imports)
            }
        }
    }

    /// `use std::module` or `use std::module::item`.
    fn use_std(&mut self, from: FileId, segs: &[Ident], span: Span, imports: &mut Vec<Import>) {
        if segs[0].name != "std" {
            self.loaded.diags.push(
                Diagnostic::error(
                    codes::UNKNOWN_MODULE,
                    format!("unknown module `{}`", segs[0].name),
                    from,
                    segs[0].span,
                )
                .with_label("only `std` modules are named this way")
                .with_help("use another file by its path in quotes: use \"common.lens\""),
            );
            return;
        }
        let Some(module) = segs.get(1) else { return };
        let Some(&(mname, _)) = STDLIB.iter().find(|(n, _)| *n == module.name) else {
            let names: Vec<&str> = STDLIB.iter().map(|(n, _)| *n).collect();
            let mut d = Diagnostic::error(
                codes::UNKNOWN_MODULE,
                format!("the standard library has no module `{}`", module.name),
                from,
                module.span,
            )
            .with_label("no such module");
            d = d.with_help(match did_you_mean(&module.name, names.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("the modules are: {}", names.join(", ")),
            });
            self.loaded.diags.push(d);
            return;
        };
        if segs.len() > 3 {
            self.loaded.diags.push(
                Diagnostic::error(
                    codes::UNKNOWN_MODULE,
                    "a `use` path names a module and at most one item",
                    from,
                    segs[3].span.to(segs[segs.len() - 1].span),
                )
                .with_label("remove this"),
            );
        }
        let file = self.std_module(mname);
        match segs.get(2) {
            Some(name) => imports.push(Import::One {
                file,
                name: name.clone(),
            }),
            None => imports.push(Import::All { file, span }),
        }
    }

    /// `use "file.lens"`, relative to the file that uses it: read once,
    /// never while it is still being loaded (a cycle), and never from
    /// outside the project root.
    fn use_file(
        &mut self,
        from: FileId,
        from_path: Option<&Path>,
        path: &str,
        pspan: Span,
        span: Span,
        imports: &mut Vec<Import>,
    ) {
        let base = from_path.and_then(Path::parent).unwrap_or(Path::new(""));
        let full = base.join(path);
        let resolved = self.fs.canonical(&full);
        if !sandbox::inside(&resolved, self.root.path()) {
            self.loaded.diags.push(outside_root(
                from,
                pspan,
                &full,
                &resolved,
                self.root.path(),
            ));
            return;
        }
        let key = Key::Path(resolved.clone());
        if let Some(&pos) = self.on_stack.get(&key) {
            let mut chain: Vec<String> = self.stack[pos..]
                .iter()
                .map(|(_, f)| self.loaded.sources.get(*f).name.clone())
                .collect();
            chain.push(self.loaded.sources.get(self.stack[pos].1).name.clone());
            self.loaded.diags.push(
                Diagnostic::error(codes::IMPORT_CYCLE, "import cycle", from, pspan)
                    .with_label("this `use` leads back to a file that is still being loaded")
                    .with_help(format!(
                        "the cycle is {}; move what both files need into a third file",
                        chain.join(" → ")
                    )),
            );
            return;
        }
        if let Some(&f) = self.keys.get(&key) {
            imports.push(Import::All { file: f, span });
            return;
        }
        if self.loaded.files.len() >= MAX_FILES {
            if !std::mem::replace(&mut self.refused_more, true) {
                self.loaded.diags.push(
                    Diagnostic::error(
                        codes::TOO_MANY_FILES,
                        format!("this `use` would load more than {MAX_FILES} files"),
                        from,
                        pspan,
                    )
                    .with_label("one file too many")
                    .with_help("a job and what it uses are at most 1000 files: join small files into larger ones"),
                );
            }
            return;
        }
        match self.fs.read(&self.root, &resolved) {
            Ok(bytes) => {
                let f = self.add(key, full.display().to_string(), Some(full), bytes);
                imports.push(Import::All { file: f, span });
            }
            Err(e) => self.loaded.diags.push(
                Diagnostic::error(
                    e.code(),
                    format!("cannot read `{}`: {e}", full.display()),
                    from,
                    pspan,
                )
                .with_label("used here")
                .with_help(match e {
                    ReadError::NotAFile { .. } => {
                        "only regular files are read: a FIFO or device could block or never end"
                            .to_string()
                    }
                    ReadError::TooLarge { limit, .. } => format!(
                        "files of at most {} MiB are read; split it into files joined by `use`",
                        limit >> 20
                    ),
                    ReadError::HardLinked { .. } => {
                        "copy the file into the project instead of linking it".to_string()
                    }
                    _ => "paths are relative to the file that uses them".to_string(),
                }),
            ),
        }
    }
}

#[cfg(all(test, target_os = "linux"))]
mod race;

/// E0107: a `use` of a file outside the project root. The file is not
/// read, so nothing of it can show in a diagnostic.
fn outside_root(
    from: FileId,
    pspan: Span,
    full: &Path,
    resolved: &Path,
    root: &Path,
) -> Diagnostic {
    Diagnostic::error(
        codes::OUTSIDE_ROOT,
        format!(
            "cannot use `{}`: it lies outside the project root `{}`",
            full.display(),
            root.display()
        ),
        from,
        pspan,
    )
    .with_label(format!("this resolves to `{}`", resolved.display()))
    .with_help(
        "a job file reads only files under its project root (by default the directory of \
         the file given on the command line); give `--root DIR` to widen it",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every standard-library module parses without a diagnostic (what
    /// `std_tree` relies on to share one tree), and two loads share the
    /// prelude's tree rather than parsing it each time.
    #[test]
    fn the_standard_library_parses_clean_and_once() {
        for (name, text) in STDLIB {
            let (_, diags) = lensc_grammar::parse(text, FileId(0));
            assert!(diags.is_empty(), "std::{name}: {diags:?}");
        }
        let fs = RealFs;
        let a = load_text(&fs, "a.lens", b"use std::machines::linuxcnc_lathe\n");
        let b = load_text(&fs, "b.lens", b"let x = 1 mm\n");
        let prelude = |l: &Loaded| {
            let i = l
                .sources
                .iter()
                .position(|(_, f)| f.name == format!("std/{PRELUDE}.lens"))
                .expect("the prelude is loaded");
            Arc::clone(&l.files[i].ast)
        };
        assert!(!prelude(&a).items.is_empty());
        assert!(Arc::ptr_eq(&prelude(&a), &prelude(&b)));
    }
}
