//! The shape of the code, kept as issue 11 left it: every source file opens with a `//!`
//! header and stays under 500 lines, and the modules' imports (`crate::…` and `super::…`
//! paths outside tests and comments) form no cycle, nor does a module import from the
//! `mod.rs` of a module that contains it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Longest source file, lines.
const MAX_FILE_LINES: usize = 500;

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, into: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, into);
        } else if path.extension().is_some_and(|ext| ext == "rs") {
            into.push(path);
        }
    }
}

/// The module a file defines, as its path from the crate root (`sim::geometry::circle`).
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let relative = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// The code of a file without its unit tests and comment lines.
fn code_of(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap();
    text.lines()
        .filter(|line| !line.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths named after each `crate::` and `super::` in `code`, relative to `module`;
/// a `{a, b::c}` group after one gives a path per member.
fn paths_in(code: &str, module: &[String]) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    for (at, keyword) in code
        .match_indices("crate::")
        .chain(code.match_indices("super::"))
    {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue; // part of a longer path (`super::super::`) or another word
        }
        let mut base: Vec<String> = if keyword == "crate::" {
            Vec::new()
        } else {
            module[..module.len().saturating_sub(1)].to_vec()
        };
        let mut rest = &code[at + keyword.len()..];
        while let Some(after) = rest.strip_prefix("super::") {
            base.pop();
            rest = after;
        }
        if let Some(group) = rest.strip_prefix('{') {
            let group = &group[..group.find('}').unwrap_or(group.len())];
            for member in group.split(',') {
                found.push([base.clone(), segments(member.trim())].concat());
            }
        } else {
            found.push([base, segments(rest)].concat());
        }
    }
    found
}

/// The leading `a::b::c` identifiers of `text`.
fn segments(text: &str) -> Vec<String> {
    let end = text
        .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
        .unwrap_or(text.len());
    text[..end]
        .split("::")
        .filter(|s| !s.is_empty() && *s != "self")
        .map(str::to_string)
        .collect()
}

#[test]
fn every_file_has_a_header_and_stays_short() {
    let mut files = Vec::new();
    rust_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        &mut files,
    );
    rust_files(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests"),
        &mut files,
    );
    assert!(files.len() > 50, "{} files", files.len());
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        assert!(
            text.starts_with("//!"),
            "{} has no //! header",
            file.display()
        );
        let lines = text.lines().count();
        assert!(
            lines <= MAX_FILE_LINES,
            "{} has {lines} lines",
            file.display()
        );
    }
}

#[test]
fn the_modules_import_each_other_without_cycles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let modules: BTreeMap<Vec<String>, String> = files
        .iter()
        .map(|file| {
            (
                module_of(&src, file),
                std::fs::read_to_string(file).unwrap(),
            )
        })
        .collect();
    let mut imports: Imports = BTreeMap::new();
    for (module, text) in &modules {
        let targets = imports.entry(module).or_default();
        for path in paths_in(&code_of(text), module) {
            // The longest prefix of the path that is a module file.
            let Some(target) = (1..=path.len())
                .rev()
                .find_map(|len| modules.get_key_value(&path[..len]).map(|(k, _)| k))
            else {
                continue;
            };
            if target == module || target.starts_with(module) {
                continue; // itself, or a module it contains
            }
            assert!(
                !module.starts_with(target),
                "{} imports from {}, a module that contains it",
                module.join("::"),
                target.join("::")
            );
            targets.insert(target);
        }
    }
    assert!(imports.values().map(BTreeSet::len).sum::<usize>() > 50);
    if let Some(cycle) = find_cycle(&imports) {
        panic!("import cycle: {}", cycle.join(" -> "));
    }
}

type Imports<'a> = BTreeMap<&'a Vec<String>, BTreeSet<&'a Vec<String>>>;

/// A cycle in `imports`, if there is one: depth first, a module met again while still on the
/// path closes it.
fn find_cycle(imports: &Imports) -> Option<Vec<String>> {
    fn visit<'a>(
        module: &'a Vec<String>,
        imports: &Imports<'a>,
        path: &mut Vec<&'a Vec<String>>,
        done: &mut BTreeSet<&'a Vec<String>>,
    ) -> Option<Vec<String>> {
        if done.contains(module) {
            return None;
        }
        if let Some(start) = path.iter().position(|m| *m == module) {
            return Some(path[start..].iter().map(|m| m.join("::")).collect());
        }
        path.push(module);
        for target in imports.get(module).into_iter().flatten() {
            if let Some(cycle) = visit(target, imports, path, done) {
                return Some(cycle);
            }
        }
        path.pop();
        done.insert(module);
        None
    }
    let mut done = BTreeSet::new();
    imports
        .keys()
        .find_map(|module| visit(module, imports, &mut Vec::new(), &mut done))
}

#[test]
fn the_import_check_sees_groups_supers_and_cycles() {
    let module: Vec<String> = ["sim", "discrete", "resolve"].map(String::from).to_vec();
    let paths = paths_in(
        "use super::detect::Contacts;\nuse crate::{app, sim::geometry::Circle};\n\
         use super::super::report::Hit;",
        &module,
    );
    let joined: Vec<String> = paths.iter().map(|p| p.join("::")).collect();
    assert_eq!(
        joined,
        [
            "app",
            "sim::geometry::Circle",
            "sim::discrete::detect::Contacts",
            "sim::report::Hit"
        ]
    );
    assert_eq!(
        code_of("//! doc\nuse crate::a;\n#[cfg(test)]\nmod tests {\n use crate::b;\n}"),
        "use crate::a;"
    );
    let (a, b, c) = (
        vec!["a".to_string()],
        vec!["b".to_string()],
        vec!["c".to_string()],
    );
    let mut imports: Imports = BTreeMap::new();
    imports.entry(&a).or_default().insert(&b);
    imports.entry(&b).or_default().insert(&c);
    assert_eq!(find_cycle(&imports), None);
    imports.entry(&c).or_default().insert(&a);
    assert_eq!(
        find_cycle(&imports),
        Some(vec!["a".into(), "b".into(), "c".into()])
    );
}
