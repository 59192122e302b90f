//! Output paths: file names from scenario names, parent directories, and the one rule every
//! output of the command line and of Python follows (logs, summaries, tables, figures,
//! recordings, JSON):
//!
//! 1. checked before any work ([`check_outputs`] for files, [`check_output_dir`] for
//!    directories): no output given twice, none an input, none an existing directory (or, for
//!    a directory, an existing file), and its directory made and writable;
//! 2. written to a temporary file in the same directory ([`temporary`]) and renamed into place
//!    ([`write_via_temporary`], [`write_file`]), so that a reader, a crash or a second writer of
//!    the same path never sees a half-written file;
//! 3. every I/O error names its path ([`LogError::File`]).

use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

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
/// ([`LogError::PathClash`], naming both roles and the path), then each one by
/// [`check_output`]. `outputs` and `inputs` are `(role, path)` pairs.
pub fn check_outputs(
    outputs: &[(String, &Path)],
    inputs: &[(String, &Path)],
) -> Result<(), LogError> {
    let ids: Vec<PathBuf> = outputs.iter().map(|(_, p)| identity(p)).collect();
    for (k, ((role, path), id)) in outputs.iter().zip(&ids).enumerate() {
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
    for (role, path) in outputs {
        check_output(path, role, "write an output")?;
    }
    Ok(())
}

/// Checks one output file for `action` (e.g. `"write the MCAP log"`) before any work: it names
/// a file ([`LogError::InvalidArgument`] for `""`, `"a/"`, `"x/.."`), is not an existing
/// directory, and its directory exists (it is made) and takes a new file ([`check_writable`]);
/// errors name the path (and `role`).
pub fn check_output(path: &Path, role: &str, action: &'static str) -> Result<(), LogError> {
    // "", "a/", "x/..": no file name to write (found by the hostile suite: such a log failed
    // only when renamed into place, after the whole flight).
    let text = path.as_os_str().to_string_lossy();
    if path.file_name().is_none() || text.ends_with('/') || text.ends_with('\\') {
        return Err(LogError::InvalidArgument {
            name: role.to_string(),
            reason: format!("`{}` names no file", path.display()),
        });
    }
    if path.is_dir() {
        return Err(LogError::File {
            action,
            path: path.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                format!("{role} is a directory"),
            ),
        });
    }
    check_writable(path, action)
}

/// Makes `path`'s directory and checks that it takes a new file (a temporary probe, removed at
/// once), for `action`; errors name `path`.
pub fn check_writable(path: &Path, action: &'static str) -> Result<(), LogError> {
    create_parent(path, action)?;
    let probe = temporary(path);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(LogError::file(action, path))?;
    std::fs::remove_file(&probe).map_err(LogError::file(action, &probe))
}

/// Checks an output directory (`role`, e.g. "the figure directory (--plots)") before any
/// work: not an existing file, made if missing, and taking new files. Errors name the path.
pub fn check_output_dir(dir: &Path, role: &str) -> Result<(), LogError> {
    const ACTION: &str = "write into the output directory";
    if dir.exists() && !dir.is_dir() {
        return Err(LogError::File {
            action: ACTION,
            path: dir.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotADirectory,
                format!("{role} is a file, not a directory"),
            ),
        });
    }
    if let Some(file) = dir.ancestors().skip(1).find(|a| a.is_file()) {
        return Err(LogError::File {
            action: ACTION,
            path: dir.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotADirectory,
                format!("`{}` is a file, not a directory", file.display()),
            ),
        });
    }
    std::fs::create_dir_all(dir).map_err(LogError::file(ACTION, dir))?;
    check_writable(&dir.join("probe"), ACTION).map_err(|e| match e {
        LogError::File { source, .. } => LogError::File {
            action: ACTION,
            path: dir.to_path_buf(),
            source,
        },
        other => other,
    })
}

/// A fresh temporary path next to `path` (same directory, so that the rename into place is
/// atomic): `.tmp-<pid>-<k>-<file name>`, keeping the extension (figure writers pick the
/// format from it). Unique within the process and across processes.
pub fn temporary(path: &Path) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let k = NEXT.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    // At most the last 200 characters (the extension kept): a name the file system takes
    // must not become one it refuses.
    let skip = name.chars().count().saturating_sub(200);
    let tail: String = name.chars().skip(skip).collect();
    path.with_file_name(format!(".tmp-{}-{k}-{tail}", std::process::id()))
}

/// Renames the finished `temporary` onto `path` (for `action`); on failure the temporary is
/// removed and the error names `path`.
pub fn rename_into_place(
    temporary: &Path,
    path: &Path,
    action: &'static str,
) -> Result<(), LogError> {
    std::fs::rename(temporary, path).map_err(|e| {
        let _ = std::fs::remove_file(temporary);
        LogError::File {
            action,
            path: path.to_path_buf(),
            source: e,
        }
    })
}

/// Writes `path` through a temporary file: makes its directory, calls `write` with the
/// temporary path, and renames it into place; if `write` fails the temporary is removed and
/// its error returned. Concurrent writers of one path each leave a whole file (the last
/// rename wins).
pub fn write_via_temporary<E: From<LogError>>(
    path: &Path,
    action: &'static str,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    create_parent(path, action)?;
    let temporary = temporary(path);
    if let Err(e) = write(&temporary) {
        let _ = std::fs::remove_file(&temporary);
        return Err(e);
    }
    Ok(rename_into_place(&temporary, path, action)?)
}

/// Writes `bytes` to `path` by [`write_via_temporary`], every error naming `path`.
pub fn write_file(path: &Path, action: &'static str, bytes: &[u8]) -> Result<(), LogError> {
    write_via_temporary(path, action, |temporary| {
        std::fs::write(temporary, bytes).map_err(LogError::file(action, path))
    })
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
        for no_file in ["", "a/", "x/.."] {
            let e = check_outputs(&[("log".into(), Path::new(no_file))], &[]).unwrap_err();
            assert!(e.to_string().contains("names no file"), "{no_file}: {e}");
        }
        assert!(check_outputs(&[("log".into(), &a), ("summary".into(), &input)], &[]).is_ok());
        // A parent that is a file is named.
        std::fs::write(tmp.join("blocker"), "").unwrap();
        let e = create_parent(&tmp.join("blocker/x/run.mcap"), "write the MCAP log").unwrap_err();
        assert!(e.to_string().contains("is a file, not a directory"), "{e}");
        std::fs::remove_dir_all(&tmp).unwrap();
    }

    #[test]
    fn outputs_are_checked_before_work_and_written_whole() {
        let tmp = std::env::temp_dir().join(format!("tvmd-paths-w-{}", std::process::id()));
        std::fs::create_dir_all(&tmp).unwrap();
        // A directory that takes no file is refused before any work, naming the path.
        #[cfg(target_os = "linux")]
        {
            let e = check_outputs(&[("summary".into(), Path::new("/proc/tvmd-x.json"))], &[])
                .unwrap_err();
            assert!(e.to_string().contains("/proc/tvmd-x.json"), "{e}");
            let e = check_output_dir(Path::new("/proc/tvmd-x"), "plots").unwrap_err();
            assert!(e.to_string().contains("/proc/tvmd-x"), "{e}");
        }
        // An output directory that is a file is named.
        let file = tmp.join("f");
        std::fs::write(&file, "keep").unwrap();
        let e = check_output_dir(&file, "the report directory").unwrap_err();
        assert!(e.to_string().contains("is a file"), "{e}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
        check_output_dir(&tmp.join("new/dir"), "plots").unwrap();
        assert!(tmp.join("new/dir").is_dir());
        // Writes go through a temporary: a failed write leaves neither it nor the target.
        let out = tmp.join("out.json");
        let failed: Result<(), LogError> = write_via_temporary(&out, "write the summary", |t| {
            std::fs::write(t, "half").unwrap();
            Err(LogError::LogFinished)
        });
        assert!(failed.is_err() && !out.exists());
        write_file(&out, "write the summary", b"whole").unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "whole");
        let left: Vec<_> = std::fs::read_dir(&tmp)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(".tmp-"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
        assert_ne!(temporary(&out), temporary(&out));
        assert_eq!(temporary(&out).extension(), out.extension());
        // A long name the file system takes stays one it takes.
        let long = tmp.join(format!("{}.mcap", "a".repeat(240)));
        check_outputs(&[("log".into(), &long)], &[]).unwrap();
        let t = temporary(&long);
        assert!(t.file_name().unwrap().len() < 230 && t.extension() == long.extension());
        std::fs::remove_dir_all(&tmp).unwrap();
    }
}
