//! Architecture invariants, checked on the source text (in the style of rust-analyzer's tidy
//! tests): the pure core imports no UI, GPU or browser crate; only `render` uses wgpu;
//! `cfg(target_arch = "wasm32")` appears only in the files ARCHITECTURE.md lists; every file is
//! written through `files::write_atomic`; every source and shader file is named in
//! ARCHITECTURE.md's code map; and the fuzz target compiles every module its modules name.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files(&path, ext, out);
        } else if path.extension().is_some_and(|e| e == ext) {
            out.push(path);
        }
    }
}

/// Source files as (path relative to the repository, code): lines that are comments are left
/// out, so a doc comment naming a crate is fine.
fn sources() -> Vec<(String, String)> {
    let mut paths = Vec::new();
    files(&root().join("src"), "rs", &mut paths);
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let rel = p
                .strip_prefix(root())
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            let code: String = std::fs::read_to_string(&p)
                .unwrap()
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n");
            (rel, code)
        })
        .collect()
}

/// Whether `code` uses crate `name` as a path (`name::` not preceded by a word character).
fn uses(code: &str, name: &str) -> bool {
    let pat = format!("{name}::");
    code.match_indices(&pat).any(|(i, _)| {
        i == 0
            || !code[..i]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_')
    })
}

const PURE: [&str; 11] = [
    "src/atmosphere.rs",
    "src/density.rs",
    "src/export/",
    "src/simulate/",
    "src/scene/",
    "src/sketch/",
    "src/field/",
    "src/derive/",
    "src/share/",
    "src/limits.rs",
    "src/seeded.rs",
];

#[test]
fn the_pure_core_imports_no_ui_gpu_or_browser_crate() {
    let mut bad = Vec::new();
    for (path, code) in sources() {
        if !PURE.iter().any(|p| path.starts_with(p)) {
            continue;
        }
        for krate in [
            "egui",
            "eframe",
            "egui_wgpu",
            "wgpu",
            "web_sys",
            "js_sys",
            "wasm_bindgen",
        ] {
            if uses(&code, krate) {
                bad.push(format!("{path} uses {krate}"));
            }
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn the_pure_core_names_no_module_above_it() {
    // By `crate::` paths as well as crates: the core is what the app, the renderer, the CLI
    // and the bench are built on, never the other way round (its unit tests included).
    let mut bad = Vec::new();
    for (path, code) in sources() {
        if !PURE.iter().any(|p| path.starts_with(p)) {
            continue;
        }
        for module in ["ui", "render", "cli", "bench", "web"] {
            if code.contains(&format!("crate::{module}::"))
                || code.contains(&format!("crate::{module};"))
            {
                bad.push(format!("{path} names crate::{module}"));
            }
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn egui_is_used_only_by_the_ui_the_viewports_paint_callbacks_and_the_two_windows() {
    // The page (`web.rs`) and the desktop window start eframe; the viewport's paint callbacks
    // are egui_wgpu's; everything else of egui is the UI's.
    let allowed = |path: &str| {
        path.starts_with("src/ui/")
            || path == "src/render/viewport.rs"
            || path == "src/cli/desktop.rs"
            || path == "src/web.rs"
    };
    let bad: Vec<String> = sources()
        .into_iter()
        .filter(|(path, code)| !allowed(path) && (uses(code, "egui") || uses(code, "eframe")))
        .map(|(path, _)| path)
        .collect();
    assert!(bad.is_empty(), "egui used elsewhere: {bad:?}");
}

#[test]
fn only_render_uses_wgpu() {
    let bad: Vec<String> = sources()
        .into_iter()
        .filter(|(path, code)| !path.starts_with("src/render/") && uses(code, "wgpu"))
        .map(|(path, _)| path)
        .collect();
    assert!(bad.is_empty(), "wgpu used outside src/render/: {bad:?}");
}

/// The code of a source file before its unit tests (`#[cfg(test)]`, by convention at the end).
fn before_tests(code: &str) -> &str {
    code.find("#[cfg(test)]").map_or(code, |i| &code[..i])
}

/// Files whose writing does not go through `files::write_atomic`: `fs::write` or `File::create`.
fn writes_in_place(code: &str) -> bool {
    let code = before_tests(code);
    code.contains("fs::write(") || code.contains("File::create(")
}

#[test]
fn every_file_is_written_through_the_one_safe_writer() {
    let bad: Vec<String> = sources()
        .into_iter()
        // `files.rs` is the writer; a module's unit tests in their own `tests.rs` may write
        // their fixtures as they like.
        .filter(|(path, code)| {
            path != "src/files.rs" && !path.ends_with("/tests.rs") && writes_in_place(code)
        })
        .map(|(path, _)| path)
        .collect();
    assert!(
        bad.is_empty(),
        "files written in place (use cloudsketch::files::write_atomic): {bad:?}"
    );
}

/// The files under `prefix` (`src/` or `src/ui/`) as (module, code before its unit tests,
/// whether at a file's end or in a `tests.rs` of their own): a folder under it is one module,
/// a file another.
fn modules_under(prefix: &str) -> Vec<(String, String)> {
    sources()
        .into_iter()
        .filter(|(path, _)| !path.ends_with("/tests.rs"))
        .filter_map(|(path, code)| {
            let rest = path.strip_prefix(prefix)?;
            let name = match rest.split_once('/') {
                Some((dir, _)) => dir.to_owned(),
                None => rest.trim_end_matches(".rs").to_owned(),
            };
            Some((name, before_tests(&code).to_owned()))
        })
        .collect()
}

/// The modules of `src/ui/` each file names (`super::x`, `crate::ui::x`, `super::{x, …}`),
/// outside its unit tests; a folder (`panels/`, `tools/`) counts as one module.
fn ui_imports() -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let mut graph = std::collections::BTreeMap::new();
    let modules = modules_under("src/ui/");
    let names: std::collections::BTreeSet<String> =
        modules.iter().map(|(n, _)| n.clone()).collect();
    // Folders: inside one, `super::` is the folder's own module.
    let modules_in_dirs: std::collections::BTreeSet<String> = sources()
        .iter()
        .filter_map(|(path, _)| path.strip_prefix("src/ui/")?.split_once('/'))
        .map(|(dir, _)| dir.to_owned())
        .collect();
    for (name, code) in &modules {
        let entry: &mut std::collections::BTreeSet<String> = graph.entry(name.clone()).or_default();
        for other in &names {
            if other == name || other == "mod" {
                continue;
            }
            let named = [
                format!("super::{other}::"),
                format!("crate::ui::{other}::"),
                format!("super::{{{other}"),
                format!(", {other}::"),
                format!("super::{other};"),
            ];
            // In a folder, `super::` is the folder's module itself: only `crate::ui::` names
            // another ui module.
            let in_folder = modules_in_dirs.contains(name);
            if named
                .iter()
                .enumerate()
                .any(|(i, pat)| (!in_folder || i == 1) && code.contains(pat.as_str()))
            {
                entry.insert(other.clone());
            }
        }
    }
    graph
}

/// Every circle of imports in `graph`, as the modules on it.
fn circles(
    graph: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
) -> Vec<Vec<String>> {
    fn walk(
        graph: &std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
        start: &str,
        path: &mut Vec<String>,
        out: &mut Vec<Vec<String>>,
    ) {
        let last = path.last().cloned().unwrap_or_default();
        for next in graph.get(&last).into_iter().flatten() {
            if next == start {
                out.push(path.clone());
            } else if next.as_str() > start && !path.contains(next) {
                path.push(next.clone());
                walk(graph, start, path, out);
                path.pop();
            }
        }
    }
    let mut out = Vec::new();
    for start in graph.keys() {
        walk(graph, start, &mut vec![start.clone()], &mut out);
    }
    out
}

#[test]
fn no_module_of_the_ui_imports_one_that_imports_it_back() {
    let found = circles(&ui_imports());
    assert!(found.is_empty(), "import circles in src/ui/: {found:?}");
}

fn architecture() -> String {
    std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap()
}

#[test]
fn wasm_cfg_appears_only_in_the_listed_files() {
    let doc = architecture();
    let line = doc
        .lines()
        .find(|l| l.contains("cfg(target_arch = \"wasm32\")") && l.contains("appears only in"))
        .expect("ARCHITECTURE.md lists where cfg(target_arch = \"wasm32\") appears");
    let listed: Vec<&str> = line.split('`').skip(1).step_by(2).collect();
    let mut bad = Vec::new();
    for (path, code) in sources() {
        let has = code.contains("target_arch = \"wasm32\"");
        if has && !listed.contains(&path.as_str()) {
            bad.push(path);
        }
    }
    assert!(
        bad.is_empty(),
        "cfg on wasm32 outside the listed files: {bad:?} (listed: {listed:?})"
    );
}

#[test]
fn every_source_and_shader_file_is_in_the_code_map() {
    let doc = architecture();
    let mut paths = Vec::new();
    files(&root().join("src"), "rs", &mut paths);
    files(&root().join("shaders"), "wgsl", &mut paths);
    let missing: Vec<String> = paths
        .iter()
        .map(|p| {
            p.strip_prefix(root())
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/")
        })
        .filter(|rel| !doc.contains(&format!("`{rel}`")))
        .collect();
    assert!(
        missing.is_empty(),
        "not in ARCHITECTURE.md's code map: {missing:#?}"
    );
}

#[test]
fn the_checks_catch_what_they_look_for() {
    // The matcher itself: a plain use is found, a longer name or a comment is not.
    assert!(uses("use wgpu::Device;", "wgpu"));
    assert!(uses("let x = wgpu::Color::RED;", "wgpu"));
    assert!(!uses("egui_wgpu::Callback::new()", "wgpu"));
    assert!(!uses("my_wgpu::x", "wgpu"));
    // The circle finder: a → b → a is one circle, a → b alone none.
    let graph = |edges: &[(&str, &str)]| {
        let mut g = std::collections::BTreeMap::<String, std::collections::BTreeSet<String>>::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    assert_eq!(circles(&graph(&[("a", "b"), ("b", "a")])).len(), 1);
    assert_eq!(
        circles(&graph(&[("a", "b"), ("b", "c"), ("c", "a")])).len(),
        1
    );
    assert!(circles(&graph(&[("a", "b"), ("b", "c")])).is_empty());
    // The writer check: a write in place is found, one in a unit test module is not.
    assert!(writes_in_place("std::fs::write(path, bytes)?;"));
    assert!(writes_in_place("let f = std::fs::File::create(&p)?;"));
    assert!(!writes_in_place(
        "files::write_atomic(p, b)?;\n#[cfg(test)]\nfs::write(p, b)"
    ));
}

/// The crate's top-level modules each names by `crate::` path (`crate::field::…`,
/// `crate::{field, …}` not used), outside unit tests: a folder or a file under `src/` is one
/// module.
fn crate_imports() -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let mut graph = std::collections::BTreeMap::<String, std::collections::BTreeSet<String>>::new();
    let sources = modules_under("src/");
    let names: std::collections::BTreeSet<String> =
        sources.iter().map(|(n, _)| n.clone()).collect();
    for (name, code) in &sources {
        let entry = graph.entry(name.clone()).or_default();
        for other in names
            .iter()
            .filter(|o| *o != name && *o != "lib" && *o != "main")
        {
            if code.contains(&format!("crate::{other}::"))
                || code.contains(&format!("crate::{other};"))
            {
                entry.insert(other.clone());
            }
        }
    }
    graph
}

#[test]
fn no_module_of_the_crate_imports_one_that_imports_it_back() {
    // The document below everything it feeds: the scene holds the simulation's settings, so
    // scene → simulate → scene is no circle; the density volume every source lands in is a
    // module of its own below `field` and `simulate`.
    let graph = crate_imports();
    assert!(
        graph["simulate"].contains("scene") && !graph["simulate"].contains("field"),
        "{graph:?}"
    );
    let found = circles(&graph);
    assert!(
        found.is_empty(),
        "import circles among the crate's modules: {found:?}"
    );
}

#[test]
fn the_fuzz_target_compiles_every_module_its_modules_name() {
    // fuzz/fuzz_targets/link_decode.rs compiles the decoders' part of the pure core from
    // ../src by `#[path]` modules; a module it compiles that names another it lacks
    // (`crate::atmosphere::…`) fails only in the sanitised nightly build, far into the suite.
    let target = std::fs::read_to_string(root().join("fuzz/fuzz_targets/link_decode.rs")).unwrap();
    let compiled: std::collections::BTreeSet<String> = target
        .lines()
        .filter_map(|l| l.trim().strip_prefix("mod "))
        .map(|m| m.trim_end_matches(';').to_string())
        .collect();
    assert!(
        compiled.contains("scene") && compiled.contains("share"),
        "{compiled:?}"
    );
    let mut missing = std::collections::BTreeSet::new();
    for (path, code) in sources() {
        let module = path
            .trim_start_matches("src/")
            .split(['/', '.'])
            .next()
            .unwrap_or_default()
            .to_string();
        if !compiled.contains(&module) {
            continue;
        }
        for (i, _) in before_tests(&code).match_indices("crate::") {
            let name: String = code[i + 7..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() && !compiled.contains(&name) {
                missing.insert(format!("{path} names crate::{name}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "not compiled by the fuzz target: {missing:#?}"
    );
}
