//! Issue 51: the layering of docs/architecture.md ("Code map") checked on the source.
//!
//! Every file under src/ is parsed (syn) and every path it names is resolved to the module it
//! reaches: `use` trees (groups, renames, globs, `self`) and every path written in code
//! (expressions, types, patterns, trait bounds, the arguments of macros that parse as
//! expressions), whether fully qualified (`crate::solver::augmentation::X` inside an
//! expression), relative (`super::super::`, `self::`, a child module's name) or through a name
//! a `use` brought in (`use crate::solver; solver::x::f()`), following re-exports
//! (`crate::solver::Model` is solver/model.rs). Comments, doc comments and string literals are
//! not code, so they are not seen.
//!
//! Modules are compared at the granularity of src/'s top-level entries (`geometry`, `error`,
//! ...) and, inside src/solver/, of its first sub-level (`solver::newton`, `solver::linear`,
//! `solver` for solver/mod.rs): a rule is stated for a module prefix and the longest prefix
//! that names a file's module decides (a rule for `solver::sparse` replaces the rule for
//! `solver` there). To add a rule, add a row to `RULES` (or `RHAI_ALLOWED`, `NO_IO`) with its
//! one-line reason; a failure prints file:line, the path as written, the module it reaches and
//! that reason.
//!
//! Code under `#[cfg(test)]` is held to the layers like the rest (a unit test that reaches up a
//! layer makes the lower layer depend on the upper one all the same), but may print (`NO_IO`
//! is about what a module does in a run).
//!
//! Printed, not checked (yet): the import cycles among the files of each folder (the solver's
//! are issue 51's circles). `print_module_graph` (ignored) prints the whole module graph.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use syn::punctuated::Punctuated;
use syn::spanned::Spanned;
use syn::visit::{self, Visit};
use syn::{Attribute, Expr, Item, ItemUse, UseTree};

// ------------------------------------------------------------------------------------------
// The rules.

/// Module `module` (and everything under it without a longer rule of its own) may use only
/// itself and the modules under the prefixes `may_use`. A rule for a part of a layer
/// (`solver::newton`) lists which parts of its layer it may use; outside the layer, the
/// layer's own rule decides (see `permits`).
struct Rule {
    module: &'static str,
    may_use: &'static [&'static str],
    reason: &'static str,
}

/// The layers of docs/architecture.md's code map, bottom up. `error`, `paths` and
/// `interrupt` are the foundation under every layer (the code map lists them between output
/// and script, but every layer from mesh up uses them: issue 51); they import nothing above
/// them. `lib` is src/lib.rs, `main` the binary's src/main.rs. A module may always use
/// itself (its rule's prefix).
#[rustfmt::skip]
const RULES: &[Rule] = &[
    // The foundation.
    Rule { module: "error", may_use: &[],
           reason: "error.rs is tribo::Error, used by every layer, so it uses none of them" },
    Rule { module: "paths", may_use: &["error"],
           reason: "paths.rs is the file policy under every layer: it knows only tribo::Error" },
    Rule { module: "interrupt", may_use: &["error"],
           reason: "interrupt.rs is the signal flag under every layer: it knows only tribo::Error" },

    // The layers.
    Rule { module: "geometry", may_use: &["error"],
           reason: "geometry knows nothing of contact, the solver or the mesh; it imports only \
                    itself and crate::{Error, Result}" },
    Rule { module: "cad", may_use: &["geometry", "error"],
           reason: "cad turns CAD files into geometry's surfaces: it uses geometry only" },
    // Until issue 51, src/contact/mod.rs broke this through a fully qualified path
    // (`impl Default for ContactSettings` took `r_fraction` from
    // `crate::solver::augmentation::MEMBRANE_FRACTION`); ContactSettings is in
    // src/solver/settings.rs since.
    Rule { module: "contact", may_use: &["geometry", "error"],
           reason: "contact sees one node and one projection at a time; it knows geometry and \
                    nothing else (no mesh, no assembly, no solver)" },
    Rule { module: "tool", may_use: &["geometry", "contact", "error"],
           reason: "a rigid tool is a surface, a schedule, a friction law and force control: it \
                    uses geometry and contact, nothing above them" },
    Rule { module: "mesh",
           may_use: &["geometry", "cad", "contact", "tool", "error", "paths", "interrupt"],
           reason: "mesh is below material, element and the solver: it uses only the layers \
                    under it" },
    Rule { module: "material",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "error", "paths", "interrupt"],
           reason: "material is below element and the solver: it uses only the layers under it" },
    Rule { module: "element",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "material",
                      "error", "paths", "interrupt"],
           reason: "elements compute one element's response and never assemble: no solver, \
                    nothing above them" },
    Rule { module: "solver",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "material", "element",
                      "error", "paths", "interrupt"],
           reason: "the solver knows nothing of files or scripts: no output, script, study, \
                    sweep or bench" },
    // The solver's wings (src/solver/mod.rs has the table): each may use the layers under
    // the solver and the wings before it, in this order: settings, sparse, model, assembly,
    // linear, newton, simulation. solver/mod.rs (module `solver`) declares them all.
    Rule { module: "solver::settings", may_use: &[],
           reason: "settings are plain values: they use nothing of the solver" },
    Rule { module: "solver::sparse", may_use: &[],
           reason: "sparse storage is under every other wing: it uses nothing of the solver" },
    Rule { module: "solver::model", may_use: &["solver::settings"],
           reason: "the model is what is solved: it knows its settings and nothing of how it \
                    is solved" },
    Rule { module: "solver::assembly",
           may_use: &["solver::settings", "solver::sparse", "solver::model"],
           reason: "assembly evaluates a trial state of the model: no linear solve, no Newton, \
                    no committed state" },
    Rule { module: "solver::linear",
           may_use: &["solver::settings", "solver::sparse", "solver::model", "solver::assembly"],
           reason: "the linear solvers (and the condensation, which reads the unknowns' layout) \
                    know nothing of Newton or the simulation" },
    Rule { module: "solver::newton",
           may_use: &["solver::settings", "solver::sparse", "solver::model", "solver::assembly",
                      "solver::linear"],
           reason: "Newton borrows the committed state it reads (newton::Newton) and never \
                    names the simulation that owns it" },
    Rule { module: "solver::simulation", may_use: &["solver"],
           reason: "the simulation is the top of the solver: it may use every wing" },
    Rule { module: "output",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "material", "element",
                      "solver", "error", "paths", "interrupt"],
           reason: "output writes what a run computes: it uses the library, never the script \
                    layer or the families of runs above it" },
    Rule { module: "script",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "material", "element",
                      "solver", "output", "error", "paths", "interrupt"],
           reason: "nothing depends on study/, sweep/ or bench/: the script layer is below them" },

    // Families of runs, on top of everything; nothing but main.rs and lib.rs uses them.
    Rule { module: "study",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "material", "element",
                      "solver", "output", "script", "error", "paths", "interrupt",
                      "sweep", "bench"],
           reason: "study is on top of everything" },
    Rule { module: "sweep",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "material", "element",
                      "solver", "output", "script", "error", "paths", "interrupt",
                      "study", "bench"],
           reason: "sweep is on top of everything" },
    Rule { module: "bench",
           may_use: &["geometry", "cad", "contact", "tool", "mesh", "material", "element",
                      "solver", "output", "script", "error", "paths", "interrupt",
                      "study", "sweep"],
           reason: "bench is on top of everything" },
    Rule { module: "lib", may_use: &[""], reason: "lib.rs declares every module" },
    Rule { module: "main", may_use: &[""], reason: "main.rs is the command line over everything" },
];

/// Only these modules name the `rhai` crate (`rhai::...`, `use rhai...`).
const RHAI_ALLOWED: &[&str] = &["script", "study", "main"];
const RHAI_REASON: &str = "nothing below script/ knows Rhai: rhai appears only in src/script/ \
                           and the layers above it (study/, main.rs); bench/ names .rhai files \
                           only";

/// Modules that write no file and print nothing, with their documented exceptions.
struct NoIo {
    module: &'static str,
    /// (file, why the doc allows it)
    except: &'static [(&'static str, &'static str)],
    reason: &'static str,
}
const NO_IO: &[NoIo] = &[NoIo {
    module: "solver",
    except: &[(
        "src/solver/linear/system_dump.rs",
        // docs/architecture.md, src/solver/: "(The one exception, `system_dump.rs`, writes
        // only when the developer variable `TRIBO_DUMP_SYSTEM` is set.)"
        "writes the system only when the developer variable TRIBO_DUMP_SYSTEM is set",
    )],
    reason: "the solver writes no file and prints nothing: results leave through \
             IncrementReport and accessors, errors through tribo::Error",
}];

/// External paths that touch files or the terminal (after imports are followed: `use
/// std::fs::File; File::create(..)` is `std::fs::File::create`).
const IO_PATHS: &[&[&str]] = &[
    &["std", "fs"],
    &["std", "io", "stdout"],
    &["std", "io", "stderr"],
    &["std", "io", "Stdout"],
    &["std", "io", "Stderr"],
    &["std", "os", "unix", "fs"],
];
/// Macros that print.
const IO_MACROS: &[&str] = &["print", "println", "eprint", "eprintln", "dbg"];

// ------------------------------------------------------------------------------------------
// The module tree and name resolution.

type ModPath = Vec<String>;
/// The module path of the binary crate's root (src/main.rs), apart from the library's `[]`.
const MAIN: &str = "#main";

#[derive(Clone, Debug, PartialEq)]
enum Target {
    /// A module of this crate (the deepest one the path reaches).
    Crate(ModPath),
    /// Anything else, with imports followed: another crate (`std::fs::write`), the prelude,
    /// or an item of the current module (`Self::new`, `Foo::Bar`).
    Other(Vec<String>),
}

struct Alias {
    /// The module whose `use` this is (the path is relative to it).
    scope: ModPath,
    segs: Vec<String>,
    leading: bool,
    /// At the module's top level (a re-export others can name), not in a function's body.
    top: bool,
}

#[derive(Default)]
struct ModInfo {
    /// The file that defines it (None: declared by `mod x;` but without a file here).
    file: Option<usize>,
    children: BTreeSet<String>,
    /// Names of the items it defines (they shadow glob imports).
    items: BTreeSet<String>,
    aliases: HashMap<String, Vec<Alias>>,
    globs: Vec<Alias>,
    declared_test: bool,
}

struct SrcFile {
    rel: String,
    key: String,
    module: ModPath,
    ast: syn::File,
}

#[derive(Default)]
struct Tree {
    files: Vec<SrcFile>,
    modules: HashMap<ModPath, ModInfo>,
    /// Paths whose resolution went round in circles (a bug of this resolver: must stay 0).
    exhausted: std::cell::Cell<usize>,
}

const FUEL: u32 = 24;

impl Tree {
    fn is_child(&self, module: &[String], name: &str) -> bool {
        self.modules
            .get(module)
            .is_some_and(|m| m.children.contains(name))
    }

    fn alias(&self, module: &[String], name: &str, local: bool) -> Option<&Alias> {
        let all = self.modules.get(module)?.aliases.get(name)?;
        all.iter()
            .find(|a| a.top)
            .or_else(|| all.iter().find(|_| local))
    }

    /// What `name` means inside `module`, if it leads somewhere: a child module, a name
    /// imported there (`local`: including imports in function bodies) or through one of its
    /// glob imports. None for the module's own items and unknown names.
    fn lookup(&self, module: &[String], name: &str, local: bool, fuel: u32) -> Option<Target> {
        if fuel == 0 {
            return None;
        }
        if self.is_child(module, name) {
            let mut m = module.to_vec();
            m.push(name.to_string());
            return Some(Target::Crate(m));
        }
        if let Some(a) = self.alias(module, name, local) {
            return Some(self.resolve(&a.scope, &a.segs, a.leading, fuel - 1));
        }
        // The module's own items shadow its glob imports.
        if self.modules.get(module)?.items.contains(name) {
            return None;
        }
        for g in self
            .modules
            .get(module)?
            .globs
            .iter()
            .filter(|g| local || g.top)
        {
            if let Target::Crate(gm) = self.resolve(&g.scope, &g.segs, g.leading, fuel - 1) {
                if gm != module {
                    if let Some(t) = self.lookup(&gm, name, false, fuel - 1) {
                        return Some(t);
                    }
                }
            }
        }
        None
    }

    /// The module (or external path) the path `segs` written in module `scope` reaches.
    fn resolve(&self, scope: &[String], segs: &[String], leading: bool, fuel: u32) -> Target {
        if fuel == 0 {
            self.exhausted.set(self.exhausted.get() + 1);
        }
        if leading || segs.is_empty() || fuel == 0 {
            return Target::Other(segs.to_vec());
        }
        let root: ModPath = if scope.first().map(String::as_str) == Some(MAIN) {
            vec![MAIN.to_string()]
        } else {
            Vec::new()
        };
        let (mut cur, mut next) = match segs[0].as_str() {
            "crate" => (root, 1),
            "self" => (scope.to_vec(), 1),
            "super" => {
                let mut m = scope.to_vec();
                let mut i = 0;
                while i < segs.len() && segs[i] == "super" {
                    m.pop();
                    i += 1;
                }
                (m, i)
            }
            "tribo" if root.first().map(String::as_str) == Some(MAIN) => (Vec::new(), 1),
            name => match self.lookup(scope, name, true, fuel) {
                Some(Target::Crate(m)) => (m, 1),
                Some(Target::Other(mut e)) => {
                    e.extend_from_slice(&segs[1..]);
                    return Target::Other(e);
                }
                None => return Target::Other(segs.to_vec()),
            },
        };
        while next < segs.len() {
            match self.lookup(&cur, &segs[next], false, fuel - 1) {
                Some(Target::Crate(m)) => cur = m,
                Some(Target::Other(mut e)) => {
                    e.extend_from_slice(&segs[next + 1..]);
                    return Target::Other(e);
                }
                None => break,
            }
            next += 1;
        }
        Target::Crate(cur)
    }

    /// The file that defines `module` (inline modules belong to their file).
    fn file_of(&self, module: &[String]) -> usize {
        let mut m = module.to_vec();
        loop {
            if let Some(file) = self.modules.get(&m).and_then(|info| info.file) {
                return file;
            }
            m.pop().expect("src/lib.rs or src/main.rs is missing");
        }
    }

    fn test_only(&self, module: &[String]) -> bool {
        (0..=module.len()).any(|n| {
            self.modules
                .get(&module[..n])
                .is_some_and(|m| m.declared_test)
        })
    }
}

/// The module path a file under src/ defines, and its module key for the rules.
fn module_of(rel: &str) -> (ModPath, String) {
    let inner = rel
        .strip_prefix("src/")
        .unwrap_or(rel)
        .strip_suffix(".rs")
        .unwrap_or(rel);
    let mut parts: Vec<String> = inner.split('/').map(str::to_string).collect();
    if parts.last().map(String::as_str) == Some("mod") {
        parts.pop();
    }
    let module = match parts.as_slice() {
        [one] if one == "lib" => Vec::new(),
        [one] if one == "main" => vec![MAIN.to_string()],
        _ => parts.clone(),
    };
    let key = match parts.as_slice() {
        [top] if top == "lib" || top == "main" => top.clone(),
        [solver, wing, ..] if solver == "solver" => format!("solver::{wing}"),
        [top, ..] => top.clone(),
        [] => "lib".to_string(),
    };
    (module, key)
}

/// `a` is `prefix` or under it ("" is everything).
fn under(a: &str, prefix: &str) -> bool {
    prefix.is_empty() || a == prefix || a.strip_prefix(prefix).is_some_and(|r| r.starts_with("::"))
}

fn is_cfg_test(attrs: &[Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg") && {
            let tokens = a
                .meta
                .require_list()
                .map(|l| l.tokens.to_string())
                .unwrap_or_default();
            tokens
                .split(|c: char| !c.is_alphanumeric() && c != '_')
                .any(|w| w == "test")
                && !tokens.contains("not")
        }
    })
}

fn item_attrs(item: &Item) -> &[Attribute] {
    match item {
        Item::Const(i) => &i.attrs,
        Item::Enum(i) => &i.attrs,
        Item::ExternCrate(i) => &i.attrs,
        Item::Fn(i) => &i.attrs,
        Item::ForeignMod(i) => &i.attrs,
        Item::Impl(i) => &i.attrs,
        Item::Macro(i) => &i.attrs,
        Item::Mod(i) => &i.attrs,
        Item::Static(i) => &i.attrs,
        Item::Struct(i) => &i.attrs,
        Item::Trait(i) => &i.attrs,
        Item::TraitAlias(i) => &i.attrs,
        Item::Type(i) => &i.attrs,
        Item::Union(i) => &i.attrs,
        Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

/// One leaf of a `use` tree: its full path, the name it binds (None for `_`), whether it
/// is a glob, and its line.
struct UseLeaf {
    segs: Vec<String>,
    name: Option<String>,
    glob: bool,
    line: usize,
}

fn flatten_use(tree: &UseTree, prefix: &mut Vec<String>, out: &mut Vec<UseLeaf>) {
    let line = tree.span().start().line;
    let leaf = |prefix: &Vec<String>, ident: &syn::Ident, rename: Option<&syn::Ident>| {
        let mut segs = prefix.clone();
        if ident != "self" {
            segs.push(ident.to_string());
        }
        let name = match rename {
            Some(r) if r == "_" => None,
            Some(r) => Some(r.to_string()),
            None => segs.last().cloned(),
        };
        UseLeaf {
            segs,
            name,
            glob: false,
            line,
        }
    };
    match tree {
        UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            flatten_use(&p.tree, prefix, out);
            prefix.pop();
        }
        UseTree::Name(n) => out.push(leaf(prefix, &n.ident, None)),
        UseTree::Rename(r) => out.push(leaf(prefix, &r.ident, Some(&r.rename))),
        UseTree::Glob(_) => out.push(UseLeaf {
            segs: prefix.clone(),
            name: None,
            glob: true,
            line,
        }),
        UseTree::Group(g) => {
            for t in &g.items {
                flatten_use(t, prefix, out);
            }
        }
    }
}

/// Pass 1: child modules, inline modules and imports of every module.
struct Collect<'a> {
    tree: &'a mut Tree,
    file: usize,
    rel: &'a str,
    stack: ModPath,
    block_depth: usize,
}

impl<'ast> Visit<'ast> for Collect<'_> {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        assert!(
            !m.attrs.iter().any(|a| a.path().is_ident("path")),
            "{}: `#[path]` on `mod {}`: the checker maps modules to files by their names",
            self.rel,
            m.ident
        );
        let name = m.ident.to_string();
        self.tree
            .modules
            .entry(self.stack.clone())
            .or_default()
            .children
            .insert(name.clone());
        let mut child = self.stack.clone();
        child.push(name);
        let info = self.tree.modules.entry(child.clone()).or_default();
        info.declared_test |= is_cfg_test(&m.attrs);
        if let Some((_, items)) = &m.content {
            info.file = Some(self.file);
            let (saved_stack, saved_depth) =
                (std::mem::replace(&mut self.stack, child), self.block_depth);
            self.block_depth = 0;
            for item in items {
                self.visit_item(item);
            }
            self.stack = saved_stack;
            self.block_depth = saved_depth;
        }
    }

    fn visit_item(&mut self, item: &'ast Item) {
        let ident = match item {
            Item::Const(i) => Some(&i.ident),
            Item::Enum(i) => Some(&i.ident),
            Item::Fn(i) => Some(&i.sig.ident),
            Item::Macro(i) => i.ident.as_ref(),
            Item::Static(i) => Some(&i.ident),
            Item::Struct(i) => Some(&i.ident),
            Item::Trait(i) => Some(&i.ident),
            Item::TraitAlias(i) => Some(&i.ident),
            Item::Type(i) => Some(&i.ident),
            Item::Union(i) => Some(&i.ident),
            _ => None,
        };
        if let (Some(ident), 0) = (ident, self.block_depth) {
            let info = self.tree.modules.entry(self.stack.clone()).or_default();
            info.items.insert(ident.to_string());
        }
        visit::visit_item(self, item);
    }

    fn visit_block(&mut self, b: &'ast syn::Block) {
        self.block_depth += 1;
        visit::visit_block(self, b);
        self.block_depth -= 1;
    }

    fn visit_item_use(&mut self, u: &'ast ItemUse) {
        let mut leaves = Vec::new();
        flatten_use(&u.tree, &mut Vec::new(), &mut leaves);
        let info = self.tree.modules.entry(self.stack.clone()).or_default();
        for l in leaves {
            let alias = Alias {
                scope: self.stack.clone(),
                segs: l.segs,
                leading: u.leading_colon.is_some(),
                top: self.block_depth == 0,
            };
            if l.glob {
                info.globs.push(alias);
            } else if let Some(name) = l.name {
                info.aliases.entry(name).or_default().push(alias);
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Use,
    Path,
    Macro,
}

/// A path found in a file, resolved.
#[derive(Debug)]
struct Occ {
    file: usize,
    line: usize,
    written: String,
    target: Target,
    kind: Kind,
    test: bool,
    /// A `pub use` (a re-export: what the module offers, not what its code uses).
    reexport: bool,
}

/// Pass 2: every path of a file, resolved.
struct Scan<'a> {
    tree: &'a Tree,
    file: usize,
    stack: ModPath,
    test_depth: usize,
    out: Vec<Occ>,
}

fn path_segs(p: &syn::Path) -> Vec<String> {
    p.segments.iter().map(|s| s.ident.to_string()).collect()
}

impl Scan<'_> {
    fn push(&mut self, line: usize, written: String, target: Target, kind: Kind, reexport: bool) {
        let test = self.test_depth > 0 || self.tree.test_only(&self.stack);
        self.out.push(Occ {
            file: self.file,
            line,
            written,
            target,
            kind,
            test,
            reexport,
        });
    }

    fn with_test<F: FnOnce(&mut Self)>(&mut self, attrs: &[Attribute], f: F) {
        let t = is_cfg_test(attrs) as usize;
        self.test_depth += t;
        f(self);
        self.test_depth -= t;
    }
}

impl<'ast> Visit<'ast> for Scan<'_> {
    fn visit_item(&mut self, item: &'ast Item) {
        self.with_test(item_attrs(item), |s| visit::visit_item(s, item));
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        self.with_test(&f.attrs, |s| visit::visit_impl_item_fn(s, f));
    }

    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if let Some((_, items)) = &m.content {
            self.stack.push(m.ident.to_string());
            for item in items {
                self.visit_item(item);
            }
            self.stack.pop();
        }
    }

    fn visit_item_use(&mut self, u: &'ast ItemUse) {
        let mut leaves = Vec::new();
        flatten_use(&u.tree, &mut Vec::new(), &mut leaves);
        let leading = u.leading_colon.is_some();
        for l in leaves {
            let target = self.tree.resolve(&self.stack, &l.segs, leading, FUEL);
            let mut written = format!("{}{}", if leading { "::" } else { "" }, l.segs.join("::"));
            if l.glob {
                written.push_str("::*");
            }
            let reexport = !matches!(u.vis, syn::Visibility::Inherited);
            self.push(l.line, written, target, Kind::Use, reexport);
        }
    }

    /// `pub(in crate::solver)` names where an item is visible, not what the code uses.
    fn visit_visibility(&mut self, _: &'ast syn::Visibility) {}

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let segs = path_segs(p);
        let leading = p.leading_colon.is_some();
        if segs.len() >= 2 || leading {
            let first = segs[0].as_str();
            let relative = matches!(first, "crate" | "self" | "super" | "Self")
                || (first == "tribo" && self.stack.first().map(String::as_str) == Some(MAIN))
                || self.tree.is_child(&self.stack, first);
            let target = self.tree.resolve(&self.stack, &segs, leading, FUEL);
            // A path through an imported name reaches what its `use` reaches (already
            // reported there) unless it goes further (`use crate::solver; solver::x::f()`).
            let repeats_use = !relative
                && !leading
                && match (
                    &target,
                    self.tree.resolve(&self.stack, &segs[..1], false, FUEL),
                ) {
                    (Target::Crate(m), Target::Crate(a)) => {
                        self.tree.file_of(m) == self.tree.file_of(&a)
                    }
                    _ => false,
                };
            if !repeats_use {
                let written = format!("{}{}", if leading { "::" } else { "" }, segs.join("::"));
                self.push(p.span().start().line, written, target, Kind::Path, false);
            }
        }
        visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        let segs = path_segs(&m.path);
        let target = if segs.len() >= 2 || m.path.leading_colon.is_some() {
            self.tree
                .resolve(&self.stack, &segs, m.path.leading_colon.is_some(), FUEL)
        } else {
            Target::Other(segs.clone())
        };
        self.push(
            m.path.span().start().line,
            format!("{}!", segs.join("::")),
            target,
            Kind::Macro,
            false,
        );
        // Arguments that parse as expressions (format!, assert!, write!, vec![a, b], ...)
        // are code too.
        if let Ok(args) = m.parse_body_with(Punctuated::<Expr, syn::Token![,]>::parse_terminated) {
            for e in &args {
                self.visit_expr(e);
            }
        }
    }
}

// ------------------------------------------------------------------------------------------
// Analysis of a set of files and the checks.

/// Parses `files` ((path relative to the crate, source)) into the module tree.
fn build(files: Vec<(String, String)>) -> Tree {
    let mut tree = Tree::default();
    for (rel, src) in files {
        let ast = syn::parse_file(&src)
            .unwrap_or_else(|e| panic!("{rel}:{}: does not parse: {e}", e.span().start().line));
        let (module, key) = module_of(&rel);
        let index = tree.files.len();
        tree.modules.entry(module.clone()).or_default().file = Some(index);
        tree.files.push(SrcFile {
            rel,
            key,
            module,
            ast,
        });
    }
    let files = std::mem::take(&mut tree.files);
    for (i, f) in files.iter().enumerate() {
        let mut c = Collect {
            tree: &mut tree,
            file: i,
            rel: &f.rel,
            stack: f.module.clone(),
            block_depth: 0,
        };
        c.visit_file(&f.ast);
    }
    tree.files = files;
    tree
}

fn scan(tree: &Tree) -> Vec<Occ> {
    let mut out = Vec::new();
    for (i, f) in tree.files.iter().enumerate() {
        let mut s = Scan {
            tree,
            file: i,
            stack: f.module.clone(),
            test_depth: 0,
            out: Vec::new(),
        };
        s.visit_file(&f.ast);
        out.append(&mut s.out);
    }
    out
}

#[derive(Debug)]
struct Violation {
    file: String,
    line: usize,
    written: String,
    reaches: String,
    test: bool,
    rule: String,
    reason: &'static str,
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}:{}: `{}` reaches {}{}\n    rule {}: {}",
            self.file,
            self.line,
            self.written,
            self.reaches,
            if self.test {
                " (in #[cfg(test)] code)"
            } else {
                ""
            },
            self.rule,
            self.reason
        )
    }
}

/// The rule that decides whether a module under `rule` may use `to`: `rule` itself, but for
/// a rule of a part of a layer (`solver::newton`) and a `to` outside that layer, the
/// layer's own rule.
fn deciding(rule: &'static Rule, to: &str) -> &'static Rule {
    match rule.module.split_once("::") {
        Some((layer, _)) if !under(to, layer) => rule_for(layer).map_or(rule, |r| deciding(r, to)),
        _ => rule,
    }
}

/// Whether `rule` lets its module use `to`: itself and its `may_use`.
fn permits(rule: &Rule, to: &str) -> bool {
    under(to, rule.module) || rule.may_use.iter().any(|p| under(to, p))
}

fn rule_for(key: &str) -> Option<&'static Rule> {
    RULES
        .iter()
        .filter(|r| under(key, r.module))
        .max_by_key(|r| r.module.len())
}

fn check(tree: &Tree, occs: &[Occ]) -> Vec<Violation> {
    let mut out = Vec::new();
    for f in &tree.files {
        let declared = match f.module.split_last() {
            Some((name, parent)) if name != MAIN => tree.is_child(parent, name),
            _ => true,
        };
        let problems = [
            (
                rule_for(&f.key).is_none(),
                "a module without a rule: add its row to RULES in tests/architecture.rs and its \
                 entry to docs/architecture.md's code map",
            ),
            (
                !declared,
                "no `mod` declares this file (a `#[path]` attribute, or a file left over): the \
                 checker maps modules to files by their names",
            ),
        ];
        for (_, reason) in problems.into_iter().filter(|(bad, _)| *bad) {
            out.push(Violation {
                file: f.rel.clone(),
                line: 1,
                written: f.module.join("::"),
                reaches: "-".into(),
                test: false,
                rule: format!("for module `{}`", f.key),
                reason,
            });
        }
    }
    for o in occs {
        let from = &tree.files[o.file];
        let mut violation = |written: &str, reaches: String, rule: String, reason| {
            out.push(Violation {
                file: from.rel.clone(),
                line: o.line,
                written: written.to_string(),
                reaches,
                test: o.test,
                rule,
                reason,
            })
        };
        match &o.target {
            Target::Crate(m) => {
                let to = &tree.files[tree.file_of(m)].key;
                if to == &from.key {
                    continue;
                }
                if let Some(rule) = rule_for(&from.key).map(|r| deciding(r, to)) {
                    // A wing's unit tests may build what they test against (a Newton test
                    // builds a Simulation); the layers' rules hold for test code too.
                    if o.test && rule.module.contains("::") {
                        continue;
                    }
                    if !permits(rule, to) {
                        let only = match (rule.module.split_once("::"), rule.may_use) {
                            (Some((layer, _)), []) => format!("nothing else of {layer}"),
                            (Some((layer, _)), parts) => {
                                format!("only {} of {layer}", parts.join(", "))
                            }
                            (None, layers) => format!("only {}", layers.join(", ")),
                        };
                        violation(
                            &o.written,
                            format!("`{to}`"),
                            format!("`{}` may use {only}", rule.module),
                            rule.reason,
                        );
                    }
                }
            }
            Target::Other(segs) => {
                if segs.first().map(String::as_str) == Some("rhai")
                    && !RHAI_ALLOWED.iter().any(|p| under(&from.key, p))
                {
                    violation(
                        &o.written,
                        "the rhai crate".into(),
                        format!("rhai only in {}", RHAI_ALLOWED.join(", ")),
                        RHAI_REASON,
                    );
                }
            }
        }
        // Unit tests may print and write temporary files: the rule is about what the
        // module does in a run.
        for rule in NO_IO
            .iter()
            .filter(|r| !o.test && under(&from.key, r.module))
        {
            if rule.except.iter().any(|(file, _)| from.rel == *file) {
                continue;
            }
            let io = match (&o.kind, &o.target) {
                (Kind::Macro, Target::Other(segs)) => IO_MACROS
                    .iter()
                    .any(|m| segs.last().map(String::as_str) == Some(*m)),
                (_, Target::Other(segs)) => IO_PATHS.iter().any(|p| {
                    segs.len() >= p.len() && segs.iter().zip(p.iter()).all(|(a, b)| a == b)
                }),
                _ => false,
            };
            if io {
                let reaches = match &o.target {
                    Target::Other(s) => format!("`{}`", s.join("::")),
                    Target::Crate(_) => unreachable!(),
                };
                violation(
                    &o.written,
                    reaches,
                    format!("`{}` does no I/O", rule.module),
                    rule.reason,
                );
            }
        }
    }
    out.sort_by(|a, b| (&a.file, a.line, &a.written).cmp(&(&b.file, b.line, &b.written)));
    out.dedup_by(|a, b| {
        a.file == b.file && a.line == b.line && a.written == b.written && a.rule == b.rule
    });
    out
}

/// File-level import graph (code outside `#[cfg(test)]`, re-exports left out): file ->
/// files it names, each with the first line that names it.
type Graph = BTreeMap<usize, BTreeMap<usize, usize>>;

fn file_graph(tree: &Tree, occs: &[Occ]) -> Graph {
    let mut g = Graph::new();
    for o in occs.iter().filter(|o| !o.test && !o.reexport) {
        if let Target::Crate(m) = &o.target {
            let to = tree.file_of(m);
            if to != o.file {
                let line = g.entry(o.file).or_default().entry(to).or_insert(o.line);
                *line = (*line).min(o.line);
            }
        }
    }
    g
}

/// Strongly connected components with more than one file (Tarjan).
fn cycles(nodes: &[usize], g: &Graph) -> Vec<Vec<usize>> {
    struct T<'a> {
        g: &'a Graph,
        keep: BTreeSet<usize>,
        index: HashMap<usize, usize>,
        low: HashMap<usize, usize>,
        stack: Vec<usize>,
        on: BTreeSet<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn strong(t: &mut T, v: usize) {
        t.index.insert(v, t.next);
        t.low.insert(v, t.next);
        t.next += 1;
        t.stack.push(v);
        t.on.insert(v);
        let succ: Vec<usize> =
            t.g.get(&v)
                .into_iter()
                .flat_map(|m| m.keys())
                .copied()
                .filter(|w| t.keep.contains(w))
                .collect();
        for w in succ {
            if !t.index.contains_key(&w) {
                strong(t, w);
                let lw = t.low[&w];
                let lv = t.low.get_mut(&v).unwrap();
                *lv = (*lv).min(lw);
            } else if t.on.contains(&w) {
                let iw = t.index[&w];
                let lv = t.low.get_mut(&v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if t.low[&v] == t.index[&v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(&w);
                comp.push(w);
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g,
        keep: nodes.iter().copied().collect(),
        index: HashMap::new(),
        low: HashMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for &v in nodes {
        if !t.index.contains_key(&v) {
            strong(&mut t, v);
        }
    }
    t.out.sort();
    t.out
}

fn read_src() -> Vec<(String, String)> {
    fn walk(dir: &Path, root: &Path, out: &mut Vec<(String, String)>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, root, out);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p
                    .strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                out.push((rel, std::fs::read_to_string(&p).unwrap()));
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    walk(&root.join("src"), root, &mut out);
    out
}

// ------------------------------------------------------------------------------------------
// The tests.

#[test]
fn layers_of_docs_architecture_hold() {
    let start = std::time::Instant::now();
    let tree = build(read_src());
    let occs = scan(&tree);
    let violations = check(&tree, &occs);
    assert_eq!(
        tree.exhausted.get(),
        0,
        "the resolver went round in circles"
    );
    // A path left unresolved that starts with one of the crate's modules is one the resolver
    // missed (it would not compile otherwise): the checker must see every path.
    let top = &tree.modules[&Vec::new()].children;
    let missed: Vec<String> = occs
        .iter()
        .filter(|o| matches!(&o.target, Target::Other(s) if top.contains(&s[0])))
        .map(|o| format!("{}:{}: {}", tree.files[o.file].rel, o.line, o.written))
        .collect();
    assert!(
        missed.is_empty(),
        "unresolved paths:\n{}",
        missed.join("\n")
    );

    // Diagnostic, not (yet) a failure: the import cycles among src/solver/*.rs, and among
    // the files of every other folder.
    let g = file_graph(&tree, &occs);
    let mut folders: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, f) in tree.files.iter().enumerate() {
        let folder = f.rel.rsplit_once('/').map_or("", |(d, _)| d);
        folders.entry(folder).or_default().push(i);
    }
    for (folder, nodes) in &folders {
        for c in cycles(nodes, &g) {
            let names: Vec<&str> = c
                .iter()
                .map(|&i| tree.files[i].rel.rsplit('/').next().unwrap())
                .collect();
            println!("import cycle in {folder}/: {}", names.join(" <-> "));
            for &a in &c {
                for (&b, line) in g[&a].iter().filter(|(b, _)| c.contains(b)) {
                    let name = |i: usize| tree.files[i].rel.rsplit('/').next().unwrap();
                    println!(
                        "    {} -> {} ({}:{line})",
                        name(a),
                        name(b),
                        tree.files[a].rel
                    );
                }
            }
        }
    }
    println!(
        "{} files, {} paths resolved in {:.2?}",
        tree.files.len(),
        occs.len(),
        start.elapsed()
    );

    if !violations.is_empty() {
        let text: Vec<String> = violations.iter().map(|v| v.to_string()).collect();
        panic!(
            "{} import(s) break docs/architecture.md's layering:\n{}",
            violations.len(),
            text.join("\n")
        );
    }
}

/// The rules table keeps the families of runs on top: nothing but lib.rs, main.rs and
/// study/sweep/bench themselves may use study/, sweep/ or bench/ (docs/architecture.md:
/// "nothing depends on study/, sweep/ or bench/").
#[test]
fn nothing_may_use_the_families_of_runs() {
    const TOP: &[&str] = &["study", "sweep", "bench"];
    for r in RULES {
        if matches!(r.module, "lib" | "main") || TOP.contains(&r.module) {
            continue;
        }
        for p in r.may_use {
            assert!(
                !TOP.iter().any(|t| under(t, p) || under(p, t)),
                "rule `{}` lets it use `{p}`: nothing depends on study/, sweep/ or bench/",
                r.module
            );
        }
    }
}

/// The checker itself, on a synthetic crate with deliberate violations.
#[test]
fn checker_finds_qualified_relative_and_grouped_paths() {
    let files = vec![
        (
            "src/lib.rs",
            "pub mod contact;\npub mod error;\npub mod geometry;\npub mod solver;\n\
             pub use error::{Error, Result};\n",
        ),
        (
            "src/error.rs",
            "pub struct Error;\npub type Result<T> = std::result::Result<T, Error>;\n",
        ),
        (
            "src/geometry/mod.rs",
            "pub mod shape;\npub use shape::Shape;\n",
        ),
        ("src/geometry/shape.rs", "pub struct Shape;\n"),
        (
            "src/solver/mod.rs",
            "pub mod x;\npub mod y;\npub use y::Model;\n",
        ),
        (
            "src/solver/x.rs",
            "pub const Y: f64 = 1.0;\n\
             pub fn report() { println!(\"{}\", Y); }\n\
             #[cfg(test)]\nmod tests { fn t() { println!(\"a unit test may print\"); } }\n",
        ),
        (
            "src/solver/y.rs",
            "pub struct Model;\npub struct Z;\npub fn h() {}\n\
             use std::fs::File;\n\
             pub fn save() { let _ = File::create(\"a\"); }\n",
        ),
        (
            "src/contact/mod.rs",
            // line 1: a doc comment naming crate::solver: not code.
            "//! Uses crate::solver::x::Y in a comment only.\n\
             pub mod inner;\n\
             use crate::{geometry::{self, Shape}, Result};\n\
             use crate::{Error, solver::{x::{self}, y::Z}};\n\
             // crate::solver::y::h() in a comment\n\
             pub fn f() -> f64 {\n\
             \x20   let _s = \"crate::solver::y::h()\";\n\
             \x20   let _g: Option<geometry::Shape> = None;\n\
             \x20   crate::solver::x::Y + 1.0\n\
             }\n\
             pub fn g() -> Result<()> { let _ = Error; Ok(()) }\n\
             pub fn k() { let _ = rhai::Engine::new(); x::report(); }\n",
        ),
        (
            "src/contact/inner.rs",
            "pub fn g() {\n\
             \x20   super::super::solver::y::h();\n\
             \x20   super::super::geometry::shape::Shape;\n\
             \x20   let _m: Option<crate::solver::Model> = None;\n\
             }\n\
             #[cfg(test)]\nmod tests {\n    use super::super::super::solver::x;\n}\n",
        ),
    ];
    let tree = build(
        files
            .into_iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect(),
    );
    let occs = scan(&tree);
    let found: Vec<(String, usize, String, String)> = check(&tree, &occs)
        .into_iter()
        .map(|v| (v.file, v.line, v.written, v.reaches))
        .collect();
    let expected: Vec<(String, usize, String, String)> = [
        (
            "src/contact/inner.rs",
            2,
            "super::super::solver::y::h",
            "`solver::y`",
        ),
        (
            "src/contact/inner.rs",
            4,
            "crate::solver::Model",
            "`solver::y`",
        ),
        (
            "src/contact/inner.rs",
            8,
            "super::super::super::solver::x",
            "`solver::x`",
        ),
        ("src/contact/mod.rs", 4, "crate::solver::x", "`solver::x`"),
        (
            "src/contact/mod.rs",
            4,
            "crate::solver::y::Z",
            "`solver::y`",
        ),
        (
            "src/contact/mod.rs",
            9,
            "crate::solver::x::Y",
            "`solver::x`",
        ),
        (
            "src/contact/mod.rs",
            12,
            "rhai::Engine::new",
            "the rhai crate",
        ),
        ("src/solver/x.rs", 2, "println!", "`println`"),
        ("src/solver/y.rs", 4, "std::fs::File", "`std::fs::File`"),
        (
            "src/solver/y.rs",
            5,
            "File::create",
            "`std::fs::File::create`",
        ),
    ]
    .iter()
    .map(|(f, l, w, r)| (f.to_string(), *l, w.to_string(), r.to_string()))
    .collect();
    assert_eq!(found, expected);

    // `x::report()` (through `use crate::solver::x::{self}`) reaches what its `use` reaches:
    // reported once, at the `use`. The test module's path is marked as test code.
    let test_occ = occs
        .iter()
        .find(|o| o.written == "super::super::super::solver::x")
        .unwrap();
    assert!(test_occ.test);
    // `super::` resolves from the file's module: in src/contact/inner.rs, `super::super` is the
    // crate root; re-exports are followed (`crate::solver::Model` is solver/y.rs).
    assert_eq!(
        tree.resolve(
            &["contact".into(), "inner".into()],
            &["super".into(), "super".into()],
            false,
            FUEL
        ),
        Target::Crate(vec![])
    );
}

/// Module keys: top-level folders, and solver's first sub-level.
#[test]
fn module_keys() {
    assert_eq!(module_of("src/solver/newton.rs").1, "solver::newton");
    assert_eq!(
        module_of("src/solver/newton/mod.rs"),
        (
            vec!["solver".into(), "newton".into()],
            "solver::newton".into()
        )
    );
    assert_eq!(module_of("src/solver/linear/sparse.rs").1, "solver::linear");
    assert_eq!(module_of("src/solver/mod.rs").1, "solver");
    assert_eq!(module_of("src/geometry/bvh.rs").1, "geometry");
    assert_eq!(
        module_of("src/error.rs"),
        (vec!["error".into()], "error".into())
    );
    assert_eq!(module_of("src/main.rs"), (vec![MAIN.into()], "main".into()));
    assert_eq!(module_of("src/lib.rs"), (vec![], "lib".into()));
    assert_eq!(rule_for("solver::sparse").unwrap().module, "solver::sparse");
    assert_eq!(rule_for("solver::newton").unwrap().module, "solver::newton");
    assert_eq!(rule_for("solver::test_models").unwrap().module, "solver");
}

/// Not a check: prints the module-level graph (`cargo test --release --test architecture
/// -- --ignored --nocapture print_module_graph`), each edge with its count of paths and its
/// first file:line, and the file-level edges of `ARCH_FOLDER` (e.g. src/solver) if set.
#[test]
#[ignore]
fn print_module_graph() {
    let tree = build(read_src());
    let occs = scan(&tree);
    let mut edges: BTreeMap<(String, String), (usize, String)> = BTreeMap::new();
    for o in &occs {
        if let Target::Crate(m) = &o.target {
            let (from, to) = (&tree.files[o.file].key, &tree.files[tree.file_of(m)].key);
            if from != to {
                let e = edges
                    .entry((from.clone(), to.clone()))
                    .or_insert((0, String::new()));
                if e.0 == 0 {
                    e.1 = format!(
                        "{}:{}{}",
                        tree.files[o.file].rel,
                        o.line,
                        if o.test { " (test)" } else { "" }
                    );
                }
                e.0 += 1;
            }
        }
    }
    for ((from, to), (n, first)) in &edges {
        println!("{from:>24} -> {to:<24} {n:>4}  {first}");
    }
    if let Ok(folder) = std::env::var("ARCH_FOLDER") {
        for (from, tos) in file_graph(&tree, &occs) {
            let f = &tree.files[from].rel;
            if f.rsplit_once('/').map_or("", |(d, _)| d) == folder {
                let tos: Vec<&str> = tos.keys().map(|&t| tree.files[t].rel.as_str()).collect();
                println!("{f} -> {}", tos.join(" "));
            }
        }
    }
}
