//! Module resolution for `import`: the std-lib shipped inside the binary first, then `.rhai`
//! files the read policy allows (below the script's folder or an `--allow-read` folder).

use crate::paths::ReadPolicy;
use rhai::module_resolvers::{ModuleResolversCollection, StaticModuleResolver};
use rhai::{Engine, EvalAltResult, Module, ModuleResolver, Position, Scope, Shared};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::rc::Rc;

/// The std-lib modules, compiled into the binary so that an installed `tribo` needs no files.
const MODULES: &[(&str, &str)] = &[
    ("testing", include_str!("../../std-lib/testing.rhai")),
    ("scenes", include_str!("../../std-lib/scenes.rhai")),
    ("tools", include_str!("../../std-lib/tools.rhai")),
    (
        "numisheet93",
        include_str!("../../std-lib/numisheet93.rhai"),
    ),
];

/// Names of the embedded std-lib modules.
pub fn module_names() -> Vec<&'static str> {
    MODULES.iter().map(|(n, _)| *n).collect()
}

pub fn resolver(policy: Rc<ReadPolicy>) -> ModuleResolversCollection {
    let mut stat = StaticModuleResolver::new();
    // A plain engine compiles the std-lib: its modules use only the core language and the
    // functions they receive as arguments, never host state.
    let mut engine = Engine::new();
    engine.set_max_operations(10_000_000);
    for (name, source) in MODULES {
        let mut ast = engine
            .compile(source)
            .unwrap_or_else(|e| panic!("std-lib module '{name}' does not compile: {e}"));
        ast.set_source(format!("std-lib/{name}.rhai"));
        let module = Module::eval_ast_as_new(Scope::new(), &ast, &engine)
            .unwrap_or_else(|e| panic!("std-lib module '{name}' fails to load: {e}"));
        stat.insert(*name, module);
    }
    let mut all = ModuleResolversCollection::new();
    all.push(stat);
    all.push(PolicyResolver {
        policy,
        cache: RefCell::default(),
        loading: RefCell::default(),
    });
    all
}

/// `import "name"` -> `name.rhai` read through the [`ReadPolicy`]; modules are loaded once
/// per run and an import cycle is refused (it would recurse without end).
struct PolicyResolver {
    policy: Rc<ReadPolicy>,
    cache: RefCell<BTreeMap<PathBuf, Shared<Module>>>,
    loading: RefCell<Vec<PathBuf>>,
}

impl ModuleResolver for PolicyResolver {
    fn resolve(
        &self,
        engine: &Engine,
        _source: Option<&str>,
        path: &str,
        pos: Position,
    ) -> Result<Shared<Module>, Box<EvalAltResult>> {
        // Rhai's resolver collection accepts only these two error kinds from a resolver.
        let fail = |msg: String| -> Box<EvalAltResult> {
            Box::new(EvalAltResult::ErrorInModule(
                path.into(),
                Box::new(EvalAltResult::ErrorRuntime(msg.into(), pos)),
                pos,
            ))
        };
        let file = format!("{path}.rhai");
        let (full, source) = self
            .policy
            .read_to_string(&file, "import")
            .map_err(|e| fail(e.to_string()))?;
        if let Some(m) = self.cache.borrow().get(&full) {
            return Ok(m.clone());
        }
        if self.loading.borrow().contains(&full) {
            return Err(fail(format!("import \"{path}\": import cycle")));
        }
        let mut ast = engine.compile(&source).map_err(|e| {
            let p = e.position();
            fail(format!(
                "import \"{path}\": {file}:{}:{}: syntax error: {}",
                p.line().unwrap_or(0),
                p.position().unwrap_or(0),
                e.0
            ))
        })?;
        ast.set_source(file.clone());
        self.loading.borrow_mut().push(full.clone());
        let module = Module::eval_ast_as_new(Scope::new(), &ast, engine);
        self.loading.borrow_mut().pop();
        let module: Shared<Module> = module
            .map_err(|e| Box::new(EvalAltResult::ErrorInModule(path.into(), e, pos)))?
            .into();
        self.cache.borrow_mut().insert(full, module.clone());
        Ok(module)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_stdlib_module_compiles_and_loads() {
        let r = super::resolver(std::rc::Rc::new(crate::paths::ReadPolicy::nothing()));
        drop(r);
        assert!(super::module_names().contains(&"testing"));
    }
}
