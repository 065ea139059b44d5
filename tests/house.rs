//! The house rules a reviewer would otherwise check by eye: no file over 800 lines in src/,
//! tests/, benches/ or examples/; no import circle between source files (file A naming
//! something in file B while B names something in A, directly or through others). Read from the sources, by the paths they write:
//! `crate::a::b`, `super::c` and `crate::a::{b, c::d}`, comments and unit tests left out. A
//! file naming its own parent module (a stage's twin using `super::Scatter`) is the module
//! tree, not a circle, and is not counted. And the GPU layer exists once: only src/compute/
//! makes compute pipelines and catches the device's errors, and every WGSL stage lives in its
//! family's folder of shaders/.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const MAX_LINES: usize = 800;

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Code files below `dir`: Rust, shell and Python.
fn code_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            code_files(&path, out);
        } else if path
            .extension()
            .is_some_and(|e| e == "rs" || e == "sh" || e == "py")
        {
            out.push(path);
        }
    }
}

/// The module path of a source file: src/a/b.rs and src/a/b/mod.rs are ["a", "b"].
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// The code without comments and without the unit tests at the end of a file.
fn code(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => &text[..i],
        None => text,
    };
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every path the code names from `crate::` or `super::`, as module paths (brace groups
/// expanded one level).
fn named_paths(module: &[String], code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    let ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    for start in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(i) = code[from..].find(start) {
            let at = from + i;
            from = at + start.len();
            if at > 0 && ident(bytes[at - 1]) {
                continue;
            }
            let base: Vec<String> = if start == "crate::" {
                Vec::new()
            } else {
                // super:: of a/b.rs, and of a/b/mod.rs, is module a.
                module[..module.len().saturating_sub(1)].to_vec()
            };
            let rest = &code[from..];
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            let mut path = base.clone();
            path.extend(
                rest[..end]
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_string),
            );
            if rest[end..].starts_with('{') {
                let close = rest[end..].find('}').map_or(rest.len(), |c| end + c);
                for item in rest[end + 1..close].split(',') {
                    let item = item.split(" as ").next().unwrap_or("").trim();
                    let mut p = path.clone();
                    p.extend(
                        item.split("::")
                            .filter(|s| !s.is_empty() && *s != "self")
                            .map(str::to_string),
                    );
                    out.push(p);
                }
            } else {
                out.push(path);
            }
        }
    }
    out
}

#[test]
fn no_source_file_is_over_800_lines_and_no_import_circle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let modules: BTreeMap<Vec<String>, PathBuf> = files
        .iter()
        .map(|f| (module_of(&src, f), f.clone()))
        .collect();
    let mut long = Vec::new();
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, file) in &modules {
        let text = std::fs::read_to_string(file).unwrap();
        let lines = text.lines().count();
        if lines > MAX_LINES {
            long.push(format!("{} ({lines} lines)", file.display()));
        }
        let deps = edges.entry(module.clone()).or_default();
        for path in named_paths(module, &code(&text)) {
            // The longest prefix of the path that is a source file's module.
            let target = (1..=path.len())
                .rev()
                .map(|k| path[..k].to_vec())
                .find(|p| modules.contains_key(p));
            if let Some(t) = target
                && &t != module
                && !module.starts_with(&t)
            {
                deps.insert(t);
            }
        }
    }
    // The tests, benches and examples are read like the sources (data such as benches/results
    // is not code).
    for dir in ["tests", "benches", "examples"] {
        let mut more = Vec::new();
        code_files(&Path::new(env!("CARGO_MANIFEST_DIR")).join(dir), &mut more);
        for file in more {
            let lines = std::fs::read_to_string(&file).unwrap().lines().count();
            if lines > MAX_LINES {
                long.push(format!("{} ({lines} lines)", file.display()));
            }
        }
    }
    assert!(long.is_empty(), "files over {MAX_LINES} lines: {long:?}");
    // A circle: a path back to where it started.
    let name = |m: &Vec<String>| {
        if m.is_empty() {
            "lib".to_string()
        } else {
            m.join("/")
        }
    };
    let mut circles = Vec::new();
    for start in edges.keys() {
        let mut stack = vec![vec![start.clone()]];
        let mut seen = BTreeSet::new();
        while let Some(path) = stack.pop() {
            let last = path.last().unwrap();
            for next in edges.get(last).into_iter().flatten() {
                if next == start {
                    circles.push(
                        path.iter()
                            .chain([next])
                            .map(name)
                            .collect::<Vec<_>>()
                            .join(" -> "),
                    );
                } else if seen.insert(next.clone()) {
                    let mut p = path.clone();
                    p.push(next.clone());
                    stack.push(p);
                }
            }
        }
    }
    assert!(circles.is_empty(), "import circles: {circles:#?}");
}

/// The core library is lean: without the default features, none of the application's crates
/// (the window, the command line, the plot, the progress bars, the peer simplifier) is a
/// dependency. Read from `cargo tree`, which resolves from Cargo.lock without building.
#[test]
fn the_core_library_depends_on_no_application_crate() {
    let out = std::process::Command::new(env!("CARGO"))
        .args([
            "tree",
            "--offline",
            "--no-default-features",
            "--edges",
            "normal",
            "--prefix",
            "none",
            "--package",
            "meshslim",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("running cargo tree");
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8_lossy(&out.stdout);
    let names: BTreeSet<&str> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    for app in [
        "eframe",
        "egui",
        "clap",
        "resvg",
        "indicatif",
        "meshopt",
        "anyhow",
    ] {
        assert!(!names.contains(app), "the core depends on {app}:\n{tree}");
    }
    for core in ["wgpu", "naga", "bytemuck", "glam", "rayon"] {
        assert!(names.contains(core), "the core lost {core}:\n{tree}");
    }
}

/// One GPU layer: compute pipelines are made, and the device's errors caught, in src/compute/
/// alone (its pipeline cache and error scopes, shared by every family and the viewer), so no
/// family compiles a shared stage twice or installs a handler on a device it only borrows; and
/// the stages are written with compute's one `stage!` macro.
#[test]
fn the_gpu_layer_is_src_compute() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    let compute = root.join("src").join("compute");
    let mut outside = Vec::new();
    for file in files.iter().filter(|f| !f.starts_with(&compute)) {
        let text = code(&std::fs::read_to_string(file).unwrap());
        for call in [
            "create_compute_pipeline",
            "push_error_scope",
            "on_uncaptured_error",
            "macro_rules! stage",
        ] {
            if text.contains(call) {
                outside.push(format!("{}: {call}", file.display()));
            }
        }
    }
    assert!(
        outside.is_empty(),
        "GPU plumbing outside src/compute: {outside:#?}"
    );
}

/// shaders/ holds the includes every family shares (`*.inc.wgsl`) at the top and one folder per
/// family; no stage file sits at the top, and no two files share a file name (as
/// `shaders/mesh.wgsl`, an include, and `shaders/viewer/mesh.wgsl`, the renderer, once did).
#[test]
fn shaders_are_in_family_folders() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut names = BTreeMap::new();
    for entry in std::fs::read_dir(&root).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            for inner in std::fs::read_dir(&path).unwrap() {
                let inner = inner.unwrap().path();
                let stem = inner.file_name().unwrap().to_string_lossy().into_owned();
                names
                    .entry(stem)
                    .or_insert_with(Vec::new)
                    .push(format!("{name}/"));
            }
        } else {
            assert!(
                name.ends_with(".inc.wgsl"),
                "shaders/{name}: only includes (*.inc.wgsl) sit at the top of shaders/"
            );
            names
                .entry(name)
                .or_insert_with(Vec::new)
                .push(String::new());
        }
    }
    let twice: Vec<_> = names.iter().filter(|(_, at)| at.len() > 1).collect();
    assert!(twice.is_empty(), "shader files sharing a name: {twice:?}");
}

/// One method × backend dispatch, the library's (`simplify::simplify_on`): the backends' entry
/// points are called from src/simplify.rs alone, so the command line, the Python package and
/// the window (which keeps a `gpu` result on its own device) all run what it chooses. And one
/// owner per concern in the viewer: `ViewerApp` is implemented in app.rs (its state, set-up and
/// frame) and actions.rs (what changes several owners at once) alone; the other viewer files
/// own their own types (scene, view, camera, panel, jobs) and never name the app.
#[test]
fn one_dispatch_and_one_owner_per_viewer_concern() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    let mut wrong = Vec::new();
    for file in &files {
        let rel = file
            .strip_prefix(root.join("src"))
            .unwrap()
            .to_string_lossy();
        let text = code(&std::fs::read_to_string(file).unwrap());
        for entry in [
            "simplify_greedy(",
            "simplify_gpu(",
            "simplify_drawn(",
            "simplify_decimate(",
        ] {
            let calls = text
                .match_indices(entry)
                .filter(|(at, _)| !text[..*at].ends_with("fn "))
                .count();
            if calls > 0 && rel != "simplify.rs" {
                wrong.push(format!("src/{rel} calls {entry}..) past the dispatch"));
            }
        }
        let in_viewer = rel.starts_with("viewer/");
        let owners = ["viewer/app.rs", "viewer/actions.rs", "viewer/mod.rs"];
        if in_viewer && !owners.contains(&rel.as_ref()) && text.contains("ViewerApp") {
            wrong.push(format!("src/{rel} names ViewerApp"));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// A family is a folder: every stage in shaders/rounds/ and shaders/core/ has its CPU twin, a
/// function of the stage's name, in the file of that name in src/rounds/cpu/ (the rounds'
/// `cpu-parallel` backend, which also runs the core stages: one twin per file, as vello keeps
/// one cpu/<stage>.rs per stage), every stage in shaders/cluster/ in tests/cluster_twins/ (the
/// clustering's twins are test code), and every stage in shaders/dag/ in src/dag/; a family's
/// runner (an `impl Runner` of the compute core) lives in its own folder.
#[test]
fn each_family_is_a_folder_with_a_twin_for_every_stage() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text_of = |dir: &Path| {
        let mut files = Vec::new();
        code_files(dir, &mut files);
        files
            .iter()
            .map(|f| code(&std::fs::read_to_string(f).unwrap()))
            .collect::<Vec<_>>()
            .join("\n")
    };
    // A definition: a line of code (comments stripped) that begins with the function, public
    // or not; a doc comment or a call naming it is not a twin.
    let defines = |text: &str, stage: &str| {
        let def = format!("fn {stage}(");
        text.lines().any(|l| {
            let l = l.trim_start();
            let l = match l.strip_prefix("pub") {
                Some(rest) if rest.starts_with('(') => rest.split_once(") ").map_or("", |r| r.1),
                Some(rest) => rest.trim_start(),
                None => l,
            };
            l.starts_with(&def)
        })
    };
    let mut missing = Vec::new();
    // (shaders, twins' folder, whether each twin has the file of its stage's name)
    for (shaders, twins, own_file) in [
        ("rounds", "src/rounds/cpu", true),
        ("core", "src/rounds/cpu", true),
        ("cluster", "tests/cluster_twins", false),
        ("dag", "src/dag", false),
    ] {
        let twins_text = text_of(&root.join(twins));
        for entry in std::fs::read_dir(root.join("shaders").join(shaders)).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().into_owned();
            let Some(stage) = name.strip_suffix(".wgsl") else {
                continue;
            };
            if stage.ends_with(".inc") {
                continue;
            }
            if own_file {
                let file = root.join(twins).join(format!("{stage}.rs"));
                let text = std::fs::read_to_string(&file).map(|t| code(&t));
                if !text.is_ok_and(|t| defines(&t, stage)) {
                    missing.push(format!(
                        "shaders/{shaders}/{name}: no fn {stage} in {twins}/{stage}.rs"
                    ));
                }
            } else if !defines(&twins_text, stage) {
                missing.push(format!(
                    "shaders/{shaders}/{name}: no fn {stage} in {twins}/"
                ));
            }
        }
    }
    // One twin per file: no file of src/rounds/cpu/ defines a second stage's function.
    for entry in std::fs::read_dir(root.join("src/rounds/cpu")).unwrap() {
        let path = entry.unwrap().path();
        let own = path.file_stem().unwrap().to_string_lossy().into_owned();
        let text = code(&std::fs::read_to_string(&path).unwrap());
        for shaders in ["rounds", "core"] {
            for e in std::fs::read_dir(root.join("shaders").join(shaders)).unwrap() {
                let name = e.unwrap().file_name().to_string_lossy().into_owned();
                let stage = name.trim_end_matches(".wgsl");
                if stage != own && !stage.ends_with(".inc") && defines(&text, stage) {
                    missing.push(format!("src/rounds/cpu/{own}.rs defines {stage}'s twin"));
                }
            }
        }
    }
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    for file in &files {
        let rel = file.strip_prefix(root.join("src")).unwrap();
        let text = code(&std::fs::read_to_string(file).unwrap());
        let runs = text.lines().any(|l| {
            let l = l.trim_start();
            l.starts_with("impl") && (l.contains("Runner<") || l.contains("RoundRunner for"))
        });
        if runs
            && !["rounds", "cluster", "dag"]
                .iter()
                .any(|f| rel.starts_with(f))
        {
            missing.push(format!(
                "src/{}: a runner outside its family's folder",
                rel.display()
            ));
        }
    }
    assert!(missing.is_empty(), "{missing:#?}");
}
