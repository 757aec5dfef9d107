//! Module resolution for `import`: the std-lib shipped inside the binary first, then files
//! next to the script.

use rhai::module_resolvers::{FileModuleResolver, ModuleResolversCollection, StaticModuleResolver};
use rhai::{Engine, Module, Scope};
use std::path::Path;

/// The std-lib modules, compiled into the binary so that an installed `tribo` needs no files.
const MODULES: &[(&str, &str)] = &[
    ("testing", include_str!("../../std-lib/testing.rhai")),
    ("scenes", include_str!("../../std-lib/scenes.rhai")),
    ("tools", include_str!("../../std-lib/tools.rhai")),
];

/// Names of the embedded std-lib modules.
pub fn module_names() -> Vec<&'static str> {
    MODULES.iter().map(|(n, _)| *n).collect()
}

pub fn resolver(script_dir: Option<&Path>) -> ModuleResolversCollection {
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
    all.push(match script_dir {
        Some(dir) => FileModuleResolver::new_with_path(dir),
        None => FileModuleResolver::new(),
    });
    all
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_stdlib_module_compiles_and_loads() {
        let r = super::resolver(None);
        drop(r);
        assert!(super::module_names().contains(&"testing"));
    }
}
