//! Output paths: file names from scenario names, parent directories, and the checks that keep
//! outputs from overwriting each other or the inputs, made before a run starts.

use std::path::{Component, Path, PathBuf};

use crate::LogError;

/// A scenario name as a file stem: ASCII letters, digits, `-`, `_`, `.` and `+` kept, anything
/// else (path separators, `..`, spaces, control characters) replaced by `_`, no leading dot,
/// at most 100 characters; `"run"` if nothing is left. Outputs named after a scenario so stay
/// in their directory.
pub fn file_stem(name: &str) -> String {
    let kept: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.' | '+') {
                c
            } else {
                '_'
            }
        })
        .take(100)
        .collect();
    let trimmed = kept.trim_start_matches('.');
    if trimmed.is_empty() {
        "run".to_string()
    } else {
        trimmed.to_string()
    }
}

/// `path` made absolute (against the working directory) with `.` and `..` resolved lexically
/// and symbolic links in its existing part resolved, so that two spellings of one file
/// compare equal.
pub fn identity(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in absolute.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    // Resolve links in the longest existing prefix.
    let mut existing = out.clone();
    let mut rest = Vec::new();
    while !existing.exists() {
        match existing.file_name() {
            Some(name) => rest.push(name.to_os_string()),
            None => return out,
        }
        if !existing.pop() {
            return out;
        }
    }
    let mut resolved = existing.canonicalize().unwrap_or(existing);
    for name in rest.iter().rev() {
        resolved.push(name);
    }
    resolved
}

/// Creates `path`'s parent directories for `action` (e.g. `"write the MCAP log"`), naming an
/// ancestor that is a file rather than a directory (the OS says only "File exists").
pub fn create_parent(path: &Path, action: &'static str) -> Result<(), LogError> {
    let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) else {
        return Ok(());
    };
    if let Some(file) = dir.ancestors().find(|a| a.is_file()) {
        return Err(LogError::File {
            action,
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotADirectory,
                format!("`{}` is a file, not a directory", file.display()),
            ),
        });
    }
    std::fs::create_dir_all(dir).map_err(LogError::file(action, path))
}

/// Checks outputs before anything runs: no output is given twice and none is an input
/// ([`LogError::PathClash`], naming both roles and the path), and none is an existing directory
/// ([`LogError::File`]). `outputs` and `inputs` are `(role, path)` pairs.
pub fn check_outputs(
    outputs: &[(String, &Path)],
    inputs: &[(String, &Path)],
) -> Result<(), LogError> {
    let ids: Vec<PathBuf> = outputs.iter().map(|(_, p)| identity(p)).collect();
    for (k, ((role, path), id)) in outputs.iter().zip(&ids).enumerate() {
        if path.is_dir() {
            return Err(LogError::File {
                action: "write an output",
                path: path.to_path_buf(),
                source: std::io::Error::new(
                    std::io::ErrorKind::IsADirectory,
                    format!("{role} is a directory"),
                ),
            });
        }
        if let Some(((first, _), _)) = outputs.iter().zip(&ids).take(k).find(|(_, i)| *i == id) {
            return Err(LogError::PathClash(format!(
                "{first} and {role} are both `{}`",
                path.display()
            )));
        }
        if let Some((input, _)) = inputs.iter().find(|(_, p)| identity(p) == *id) {
            return Err(LogError::PathClash(format!(
                "{role} `{}` is the {input}: it would be overwritten",
                path.display()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn names_stay_inside_their_directory() {
        assert_eq!(file_stem("paper-tilt"), "paper-tilt");
        assert_eq!(file_stem("../../x"), "_.._x");
        assert_eq!(file_stem("/etc/passwd"), "_etc_passwd");
        assert_eq!(file_stem(".hidden"), "hidden");
        assert_eq!(file_stem(""), "run");
        assert_eq!(file_stem("a b\u{7}c"), "a_b_c");
        let dir = Path::new("out");
        for name in ["../../x", "..", "/abs", "a/../../b", "C:\\\\x"] {
            let p = dir.join(format!("{}.mcap", file_stem(name)));
            assert_eq!(p.parent(), Some(dir), "{name} -> {}", p.display());
        }
    }

    #[test]
    fn clashes_are_found_through_other_spellings() {
        let tmp = std::env::temp_dir().join(format!("tvmd-paths-{}", std::process::id()));
        std::fs::create_dir_all(tmp.join("d")).unwrap();
        let a = tmp.join("run.mcap");
        let b = tmp.join("d/../run.mcap");
        let e = check_outputs(&[("log".into(), &a), ("summary".into(), &b)], &[]).unwrap_err();
        assert!(e.to_string().contains("log and summary"), "{e}");
        let input = tmp.join("s.toml");
        let e = check_outputs(
            &[("log".into(), &input)],
            &[("scenario file".into(), &input)],
        )
        .unwrap_err();
        assert!(e.to_string().contains("scenario file"), "{e}");
        let e = check_outputs(&[("log".into(), &tmp)], &[]).unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
        assert!(check_outputs(&[("log".into(), &a), ("summary".into(), &input)], &[]).is_ok());
        // A parent that is a file is named.
        std::fs::write(tmp.join("blocker"), "").unwrap();
        let e = create_parent(&tmp.join("blocker/x/run.mcap"), "write the MCAP log").unwrap_err();
        assert!(e.to_string().contains("is a file, not a directory"), "{e}");
        std::fs::remove_dir_all(&tmp).unwrap();
    }
}
