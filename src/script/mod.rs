//! Rhai bindings: the engine that runs process scripts, and the REPL.
//!
//! Everything scripts can see is registered here (one module per group of types); nothing
//! below this module knows that Rhai exists. Scripts run sandboxed: operation, call-depth
//! and size limits, and output only below the run's output folder.

mod api_cad;
mod api_charts;
pub(crate) mod api_contact;
mod api_mesh_import;
mod api_mesh_map;
mod api_numbers;
mod api_round_blank;
mod api_scene;
mod api_shell;
mod api_sim;
mod api_steps;
mod api_strokes;
mod api_tools;
mod convert;
mod law_source;
pub mod limits;
pub(crate) mod record;
pub mod repl;
mod settings;
mod stdlib;

pub use api_sim::{ScriptSim, Simulations, DEFERRED};
pub use settings::SETTING_KEYS;

use crate::paths::ReadPolicy;
use crate::{Error, Result};
use rhai::{Dynamic, Engine, EvalAltResult, Position, Scope, AST};
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// How the host runs scripts.
#[derive(Clone, Debug)]
pub struct HostOptions {
    /// The run's output folder (VTK frames, history.csv, summary.json).
    pub out_dir: PathBuf,
    /// Show a progress bar during `sim.run()`.
    pub progress: bool,
    /// Maximum number of script operations (an endless loop stops with an error).
    pub max_operations: u64,
    /// While set (the REPL loading its script), `sim.run()` returns at once so that the
    /// person can step the scene by hand.
    pub defer_run: Rc<std::cell::Cell<bool>>,
    /// Script friction laws by tool name (`tool.friction(|work, slip, pressure| ...)`).
    pub script_laws: Rc<std::cell::RefCell<std::collections::BTreeMap<String, rhai::FnPtr>>>,
    /// The text of every script compiled for this host, by the source name its AST carries
    /// (after `--set`): where a script friction law's source is read (module `law_source`).
    pub sources: Rc<std::cell::RefCell<std::collections::BTreeMap<String, Rc<str>>>>,
    /// `tribo run --restart FILE`: the first simulation the script starts continues from
    /// this checkpoint.
    pub restart: Option<PathBuf>,
    /// Set once the restart checkpoint has been loaded.
    pub restart_used: Rc<std::cell::Cell<bool>>,
    /// Print warnings of converged increments (status cycling, limits exceeded at dt_min).
    pub warnings: bool,
    /// Settings given to every simulation the script creates, before the script's own
    /// `sim.settings(...)` calls (same keys): how a study switches the method of a script
    /// that does not declare the switch itself.
    pub base_settings: rhai::Map,
    /// Show the script's `print` output (a study running many scripts turns it off).
    pub script_print: bool,
    /// Stop request (SIGINT/SIGTERM): polled between increments and Newton iterations.
    pub interrupt: crate::interrupt::Interrupt,
    /// The simulations the script created (the host records stops in their folders).
    pub simulations: Simulations,
    /// Folders scripts may read besides their own (`--allow-read DIR`).
    pub allow_read: Vec<PathBuf>,
    /// Largest file a script may read (imports, JSON tables), in bytes.
    pub max_read_bytes: u64,
    /// Memory, script time, increments and output size ([`limits`]).
    pub limits: limits::Limits,
    /// The script's own time (the engine sets a fresh one).
    pub clock: Rc<limits::ScriptClock>,
    /// What [`run_file`] does with an earlier run's files in the output folder.
    pub earlier_outputs: EarlierOutputs,
    /// Names of node sets `mesh.select` made after a simulation existed: a simulation holds
    /// the copy of the mesh it was created with, so such a set never reaches it; an error
    /// that names one as unknown says so ([`explain_late_sets`]).
    pub late_sets: Rc<std::cell::RefCell<std::collections::BTreeSet<String>>>,
}

/// What a run does with the files an earlier run left in its output folder (the engine's
/// own files only: `crate::output::previous_outputs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EarlierOutputs {
    /// Leave them (a restart continues the run in its folder; library callers that manage
    /// their folders themselves).
    #[default]
    Keep,
    /// Refuse the run, naming the folder, the files and `--overwrite` (`tribo run`).
    Refuse,
    /// Remove them before the run starts (`tribo run --overwrite`, the REPL's own folder).
    Overwrite,
}

/// Applies `policy` to the earlier run's files in `dir` (to be called with the folder's
/// lock held, so that no run is writing them).
pub fn prepare_output_folder(dir: &Path, policy: EarlierOutputs) -> Result<()> {
    if policy == EarlierOutputs::Keep {
        return Ok(());
    }
    let files = crate::output::previous_outputs(dir)?;
    if files.is_empty() {
        return Ok(());
    }
    if policy == EarlierOutputs::Overwrite {
        crate::output::clear_previous_outputs(dir)?;
        return Ok(());
    }
    Err(Error::Input(format!(
        "the output folder {} holds an earlier run's results ({})\n  \
         add --overwrite to remove them first (only the files a run writes: history.csv, \
         summary.json, *.pvd, charts, frames/*.vtu, checkpoints/*.json),\n  \
         or choose another --out, or continue that run with --restart CHECKPOINT",
        dir.display(),
        crate::output::describe_outputs(dir, &files)
    )))
}

impl Default for HostOptions {
    fn default() -> Self {
        HostOptions {
            out_dir: PathBuf::from("out"),
            progress: false,
            max_operations: 50_000_000,
            defer_run: Rc::new(std::cell::Cell::new(false)),
            script_laws: Rc::default(),
            sources: Rc::default(),
            restart: None,
            restart_used: Rc::default(),
            warnings: true,
            base_settings: rhai::Map::new(),
            script_print: true,
            interrupt: crate::interrupt::Interrupt::new(),
            simulations: Simulations::default(),
            allow_read: Vec::new(),
            max_read_bytes: crate::paths::DEFAULT_MAX_READ_BYTES,
            limits: limits::Limits::default(),
            clock: Rc::default(),
            earlier_outputs: EarlierOutputs::Keep,
            late_sets: Rc::default(),
        }
    }
}

/// Builds a sandboxed engine with the tribo API and the std-lib module resolver.
pub fn engine(host: &HostOptions, script_dir: Option<&Path>) -> Engine {
    let mut engine = Engine::new();
    engine.set_max_operations(host.max_operations);
    engine.set_max_call_levels(64);
    engine.set_max_expr_depths(128, 64);
    engine.set_max_string_size(limits::MAX_STRING);
    engine.set_max_array_size(host.limits.max_array);
    engine.set_max_map_size(host.limits.max_map);
    let policy = Rc::new(read_policy(host, script_dir).unwrap_or_else(|_| ReadPolicy::nothing()));
    engine.set_module_resolver(stdlib::resolver(policy.clone()));
    if !host.script_print {
        engine.on_print(|_| {});
    }
    let mut host = host.clone();
    host.clock = Rc::default();
    let (limits, clock) = (host.limits.clone(), host.clock.clone());
    let interrupt = host.interrupt.clone();
    engine.on_progress(move |ops| {
        limits::progress_check(&limits, &clock, &interrupt, ops).map(Dynamic::from)
    });
    // Maps grown by index assignment, which Rhai's size check misses (module `limits`).
    let (map_limits, map_reads) = (host.limits.clone(), std::cell::Cell::new(0u64));
    // `on_var` is marked deprecated only as "volatile" (Rhai's own note): it is supported.
    #[allow(deprecated)]
    engine.on_var(move |name, _, ctx| match ctx.scope().get(name) {
        Some(value) if limits::map_over_bound(&map_limits, value, &map_reads) => Err(Box::new(
            EvalAltResult::ErrorDataTooLarge("Size of object map".into(), Position::NONE),
        )),
        _ => Ok(None),
    });
    let host = Rc::new(host);
    api_scene::register(&mut engine, host.clone());
    api_cad::register(&mut engine, policy.clone());
    api_mesh_import::register(&mut engine, policy.clone(), host.limits.clone());
    api_round_blank::register(&mut engine, host.limits.clone());
    api_tools::register(&mut engine, policy);
    api_sim::register(&mut engine, host.clone());
    api_steps::register(&mut engine);
    api_strokes::register(&mut engine);
    api_charts::register(&mut engine, host);
    api_mesh_map::register(&mut engine);
    api_shell::register(&mut engine);
    api_numbers::register(&mut engine);
    record::register(&mut engine);
    register_checks(&mut engine);
    engine
}

/// Where the script at `script_dir` may read: its folder and the `--allow-read` folders
/// (an error names a folder that cannot be opened).
pub fn read_policy(host: &HostOptions, script_dir: Option<&Path>) -> Result<ReadPolicy> {
    ReadPolicy::new(
        script_dir.unwrap_or(Path::new(".")),
        &host.allow_read,
        host.max_read_bytes,
    )
}

/// Assertions for scripted test cases: a failed one stops the script with its message.
fn register_checks(engine: &mut Engine) {
    engine.register_fn(
        "assert",
        |cond: bool, msg: &str| -> convert::ScriptResult<()> {
            if cond {
                Ok(())
            } else {
                Err(Box::new(EvalAltResult::ErrorRuntime(
                    format!("assertion failed: {msg}").into(),
                    Position::NONE,
                )))
            }
        },
    );
    engine.register_fn(
        "assert_close",
        |a: f64, b: f64, rel: f64, msg: &str| -> convert::ScriptResult<()> {
            // A non-finite value is never close to anything (inf - 1 <= 0.1 inf would pass).
            let scale = a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
            let finite = a.is_finite() && b.is_finite() && rel.is_finite() && rel >= 0.0;
            if finite && (a - b).abs() <= rel * scale {
                Ok(())
            } else {
                Err(Box::new(EvalAltResult::ErrorRuntime(
                    format!(
                        "assertion failed: {msg}: {a} and {b} differ by more than {rel} relative"
                    )
                    .into(),
                    Position::NONE,
                )))
            }
        },
    );
}

/// `message`, and when it names as unknown a node set that `mesh.select` made after a
/// simulation was created, why, on a line of its own: a simulation holds the copy of the
/// mesh it was created with.
pub fn explain_late_sets(host: &HostOptions, message: String) -> String {
    let late = host.late_sets.borrow();
    let named = late
        .iter()
        .find(|name| message.contains(&format!("node set = \"{name}\" is unknown")));
    match named {
        Some(name) => format!(
            "{message}\n  mesh.select(\"{name}\", ...) ran after simulation(mesh, ...): a \
             simulation takes its own copy of the mesh when it is created, so a set selected \
             later never reaches it; select every set before simulation(...)"
        ),
        None => message,
    }
}

/// Formats a Rhai error as "file:line:column: message". An error inside a function of
/// another source (a std-lib module) is reported where this file called it; a size bound
/// is named with its value and option (`limits`).
pub fn describe_error(file: &str, err: &EvalAltResult, limits: &limits::Limits) -> String {
    let pos = innermost_position(file, err);
    let msg = message(err, limits);
    match (pos.line(), pos.position()) {
        (Some(l), Some(c)) => format!("{file}:{l}:{c}: {msg}"),
        (Some(l), None) => format!("{file}:{l}: {msg}"),
        _ => format!("{file}: {msg}"),
    }
}

/// The message of an error, with a limit's own text for a script the progress check stopped.
fn message(err: &EvalAltResult, limits: &limits::Limits) -> String {
    match err {
        EvalAltResult::ErrorTerminated(why, _) => format!("stopped: {why}"),
        EvalAltResult::ErrorDataTooLarge(what, _) => limits::data_too_large(what, limits),
        EvalAltResult::ErrorInFunctionCall(_, _, inner, _) => {
            if let EvalAltResult::ErrorTerminated(..) | EvalAltResult::ErrorDataTooLarge(..) =
                &**inner
            {
                message(inner, limits)
            } else {
                err.to_string()
            }
        }
        other => other.to_string(),
    }
}

fn innermost_position(file: &str, err: &EvalAltResult) -> Position {
    match err {
        EvalAltResult::ErrorInFunctionCall(_, source, inner, pos) => {
            let p = innermost_position(file, inner);
            let same_file = source.is_empty() || source.as_str() == file;
            if p.is_none() || !same_file {
                *pos
            } else {
                p
            }
        }
        EvalAltResult::ErrorInModule(_, _, pos) => *pos,
        other => other.position(),
    }
}

/// Parses a `--set NAME=VALUE` value: integer, float, boolean, else a string.
pub fn parse_override(text: &str) -> Result<(String, Dynamic)> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| Error::Input(format!("--set '{text}' must have the form NAME=VALUE")))?;
    let name = name.trim();
    if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
        return Err(Error::Input(format!(
            "--set name '{name}' is not a valid variable name"
        )));
    }
    let v = value.trim();
    let dynamic = if let Ok(i) = v.parse::<i64>() {
        Dynamic::from(i)
    } else if let Ok(f) = v.parse::<f64>() {
        if !f.is_finite() {
            return Err(Error::Input(format!(
                "--set {name}={v}: the value must be a finite number"
            )));
        }
        Dynamic::from(f)
    } else if let Ok(b) = v.parse::<bool>() {
        Dynamic::from(b)
    } else {
        Dynamic::from(v.trim_matches('"').to_string())
    };
    Ok((name.to_string(), dynamic))
}

/// Compiles a script file, naming the file in errors.
pub fn compile(engine: &Engine, path: &Path) -> Result<AST> {
    compile_source(engine, path).map(|(ast, _)| ast)
}

/// [`compile`], also returning the script's text.
fn compile_source(engine: &Engine, path: &Path) -> Result<(AST, String)> {
    let source =
        crate::paths::read_named_text(path, crate::paths::DEFAULT_MAX_READ_BYTES, "script")?;
    let file = path.display().to_string();
    let mut ast = engine.compile(&source).map_err(|e| {
        let p = e.position();
        Error::Script(format!(
            "{file}:{}:{}: syntax error: {}",
            p.line().unwrap_or(0),
            p.position().unwrap_or(0),
            e.0
        ))
    })?;
    ast.set_source(file);
    Ok((ast, source))
}

/// Keeps `text`, the script compiled as `path`, where a script friction law's source is
/// looked up (module `law_source`).
fn remember_source(host: &HostOptions, path: &Path, text: String) {
    let name = path.display().to_string();
    host.sources.borrow_mut().insert(name, text.into());
}

/// Runs a script file to its end.
///
/// Every stop is recorded in the output folder of each simulation the script started:
/// summary.json with the status ("stopped", or "interrupted" after a signal) and the
/// reason, and checkpoints/final.json with the last converged state (see
/// `SimState::record_stop`). An interrupt returns `Error::Interrupted`. A `--restart`
/// checkpoint that no simulation used is an error.
pub fn run_file(path: &Path, overrides: &[(String, Dynamic)], host: &HostOptions) -> Result<()> {
    host.simulations.clear();
    host.late_sets.borrow_mut().clear();
    let engine = engine(host, path.parent());
    let (ast, source) = compile_source(&engine, path)?;
    // The --allow-read folders exist (the engine would otherwise refuse every read quietly).
    read_policy(host, path.parent())?;
    // Held to the end of the run: a second run into the same folder is refused.
    let _lock = crate::output::FolderLock::acquire(&host.out_dir)?;
    prepare_output_folder(&host.out_dir, host.earlier_outputs)?;
    let (ast, text) = overridden(&engine, ast, overrides, path)?;
    remember_source(host, path, text.unwrap_or(source));
    let mut scope = Scope::new();
    let outcome = engine
        .run_ast_with_scope(&mut scope, &ast)
        .map_err(|e| {
            let text = describe_error(&path.display().to_string(), &e, &host.limits);
            Error::Script(explain_late_sets(host, text))
        })
        .and_then(|()| host.simulations.close());
    let outcome = outcome.and_then(|()| match &host.restart {
        Some(file) if !host.restart_used.get() => Err(Error::Input(format!(
            "--restart {}: the script {} started no simulation, so the checkpoint was not used",
            file.display(),
            path.display()
        ))),
        _ => Ok(()),
    });
    match outcome {
        Ok(()) => Ok(()),
        Err(err) if host.interrupt.is_raised() => {
            let why = host.interrupt.reason();
            host.simulations.record_stop("interrupted", &why);
            let _ = err;
            Err(Error::Interrupted(why))
        }
        Err(err) => {
            host.simulations.record_stop("stopped", &err.to_string());
            Err(err)
        }
    }
}

/// `--set NAME=VALUE` replaces the value of the script's top-level `let NAME = ...;`
/// (its default), so one script serves a family of runs. A name the script never declares
/// is an error (a typo would otherwise be silently ignored).
pub fn apply_overrides(
    engine: &Engine,
    ast: AST,
    overrides: &[(String, Dynamic)],
    path: &Path,
) -> Result<AST> {
    overridden(engine, ast, overrides, path).map(|(ast, _)| ast)
}

/// [`apply_overrides`], also returning the script's text after them (`None`: no override).
fn overridden(
    engine: &Engine,
    ast: AST,
    overrides: &[(String, Dynamic)],
    path: &Path,
) -> Result<(AST, Option<String>)> {
    if overrides.is_empty() {
        return Ok((ast, None));
    }
    for (i, (name, _)) in overrides.iter().enumerate() {
        if overrides[..i].iter().any(|(n, _)| n == name) {
            return Err(Error::Input(format!(
                "--set {name} is given more than once; give each name once"
            )));
        }
    }
    let source =
        crate::paths::read_named_text(path, crate::paths::DEFAULT_MAX_READ_BYTES, "script")?;
    let mut patched = String::new();
    let mut seen = vec![false; overrides.len()];
    for line in source.lines() {
        let trimmed = line.trim_start();
        let mut replaced = false;
        for (i, (name, value)) in overrides.iter().enumerate() {
            let prefix = format!("let {name} =");
            if !seen[i] && trimmed.starts_with(&prefix) && !line.starts_with(char::is_whitespace) {
                let code = line.split("//").next().unwrap_or("").trim_end();
                if !code.ends_with(';') {
                    return Err(Error::Input(format!(
                        "--set {name}: the declaration `{}` in {} must fit on one line ending with ';'",
                        line.trim(),
                        path.display()
                    )));
                }
                let declared = code
                    .split_once('=')
                    .map_or("", |(_, d)| d.trim().trim_end_matches(';').trim());
                let value = as_declared(value, declared).map_err(|kind| {
                    Error::Input(format!(
                        "--set {name}={}: the script declares {kind} (`{}`)",
                        literal(value),
                        code.trim()
                    ))
                })?;
                patched.push_str(&format!("let {name} = {};", literal(&value)));
                seen[i] = true;
                replaced = true;
                break;
            }
        }
        if !replaced {
            patched.push_str(line);
        }
        patched.push('\n');
    }
    if let Some(i) = seen.iter().position(|s| !s) {
        return Err(Error::Input(format!(
            "--set {}: the script {} has no top-level `let {} = ...;` to override; it declares: {}",
            overrides[i].0,
            path.display(),
            overrides[i].0,
            declared_names(&source).join(", ")
        )));
    }
    let file = path.display().to_string();
    let mut ast = engine
        .compile(&patched)
        .map_err(|e| Error::Script(format!("{file}: after --set: {e}")))?;
    ast.set_source(file);
    Ok((ast, Some(patched)))
}

/// The names of the script's top-level `let NAME = ...;` lines (what `--set` can override).
fn declared_names(source: &str) -> Vec<String> {
    source
        .lines()
        .filter(|l| !l.starts_with(char::is_whitespace))
        .filter_map(|l| l.strip_prefix("let "))
        .filter_map(|l| l.split_once('=').map(|(n, _)| n.trim().to_string()))
        .filter(|n| !n.is_empty() && n.chars().all(|c| c.is_alphanumeric() || c == '_'))
        .collect()
}

/// An integer given for a declaration written as a float literal (`let step = 0.5;` with
/// `--set step=1`) becomes a float, so the script's float arithmetic keeps working. A value
/// of another kind than a literal declaration's (text for a number, a number for a boolean)
/// is refused with the kind declared: the script would fail later, far from the cause.
fn as_declared(value: &Dynamic, declared: &str) -> std::result::Result<Dynamic, &'static str> {
    let int_literal = declared.parse::<i64>().is_ok();
    let float_literal = declared.parse::<f64>().is_ok() && !int_literal;
    let bool_literal = declared == "true" || declared == "false";
    let number = value.is_int() || value.is_float();
    match value.as_int() {
        Ok(i) if float_literal => Ok(Dynamic::from(i as f64)),
        _ if (int_literal || float_literal) && !number => Err("a number"),
        _ if bool_literal && !value.is_bool() => Err("true or false"),
        _ => Ok(value.clone()),
    }
}

fn literal(v: &Dynamic) -> String {
    if let Some(s) = v.clone().try_cast::<String>() {
        format!("{s:?}")
    } else if let Some(f) = v.clone().try_cast::<f64>() {
        format!("{f:?}")
    } else {
        v.to_string()
    }
}
