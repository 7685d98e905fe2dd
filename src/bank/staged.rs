//! Files written in two steps: the whole content to a temporary file beside the destination,
//! then a rename over it. A command writing several files stages them all before committing
//! any, so a failure leaves every destination as it was.
//!
//! The destination is where the path leads ([`destination`]): a symbolic link is followed and
//! its target replaced (the link stays a link), an existing file keeps its permissions (and, as
//! root, its owner), and anything but a regular file (a directory, a device, a named pipe, a
//! socket) is refused.

use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use tempfile::NamedTempFile;

/// A file's new content, written and synced to a temporary file in the destination's directory,
/// waiting to replace the destination. Dropped without [`commit`](Self::commit), it removes the
/// temporary file and the destination is untouched.
#[derive(Debug)]
pub struct StagedFile {
    /// The temporary file holding the content.
    temp: NamedTempFile,
    /// Where the content goes.
    path: PathBuf,
}

impl StagedFile {
    /// Writes `content` to a temporary file named `.{prefix}-*.tmp` beside `path`.
    pub fn write(path: &Path, prefix: &str, content: &[u8]) -> io::Result<Self> {
        let destination = destination(path)?;
        let mut temp = temp_beside(&destination, &format!(".{prefix}-"), ".tmp")?;
        temp.write_all(content)?;
        temp.as_file().sync_all()?;
        Ok(Self {
            temp,
            path: destination.path,
        })
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the content over the destination, atomically.
    pub fn commit(self) -> io::Result<()> {
        self.temp
            .persist(&self.path)
            .map(|_| ())
            .map_err(|e| e.error)
    }
}

/// Every temporary file this process made beside a destination: a signal that ends the process
/// removes those still there ([`exit_removing_temporaries`]). Those renamed into place or dropped are
/// gone already.
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Makes a temporary file with `create` and notes it for [`exit_removing_temporaries`], both
/// under the registry's lock: a signal handled meanwhile waits until the file is noted, so it
/// cannot miss one.
fn tracked<T>(create: impl FnOnce() -> io::Result<T>, path: impl Fn(&T) -> &Path) -> io::Result<T> {
    let mut paths = match TEMPORARIES.lock() {
        Ok(paths) => paths,
        Err(poisoned) => poisoned.into_inner(),
    };
    let made = create()?;
    // Forget those already gone, so a long session's list stays short.
    paths.retain(|p| p.exists());
    paths.push(path(&made).to_path_buf());
    Ok(made)
}

/// Removes every temporary file this process made that is still there, then ends the process
/// with `code`: for a process ended by a signal, whose destructors do not run. The registry
/// stays locked until the end, so no temporary file can be made after the sweep. The
/// destinations keep what they held (a set of files interrupted halfway through
/// [`commit_all`] keeps the ones already replaced).
pub fn exit_removing_temporaries(code: i32) -> ! {
    let paths = match TEMPORARIES.lock() {
        Ok(paths) => paths,
        Err(poisoned) => poisoned.into_inner(),
    };
    for path in paths.iter() {
        let _ = std::fs::remove_file(path);
    }
    std::process::exit(code)
}

/// Where a file written to a path lands.
#[derive(Debug, Clone)]
pub struct Destination {
    /// The path itself, or the file a symbolic link there leads to.
    pub path: PathBuf,
    /// The permissions of the regular file there now, kept by the new one; `None` when there is
    /// no file yet.
    pub permissions: Option<std::fs::Permissions>,
    /// The owner (user and group ids) of the regular file there now, kept by the new one when
    /// this process may give it to them (as root); `None` when there is no file yet.
    pub owner: Option<(u32, u32)>,
}

/// Most symbolic links followed in a row, as the kernel's `ELOOP` limit.
const MAX_LINKS: usize = 40;

/// Where writing to `path` lands: symbolic links followed (a dangling one to the file it names),
/// and what is there now, which must be a regular file or nothing. The error for anything else
/// says what it is.
pub fn destination(path: &Path) -> io::Result<Destination> {
    let mut path = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match std::fs::symlink_metadata(&path) {
            Ok(meta) => meta,
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Ok(Destination {
                    path,
                    permissions: None,
                    owner: None,
                })
            }
            Err(e) => return Err(e),
        };
        let kind = meta.file_type();
        if kind.is_symlink() {
            let target = std::fs::read_link(&path)?;
            path = match path.parent() {
                Some(dir) if target.is_relative() => dir.join(target),
                _ => target,
            };
            continue;
        }
        if kind.is_file() {
            #[cfg(unix)]
            let owner = {
                use std::os::unix::fs::MetadataExt;
                Some((meta.uid(), meta.gid()))
            };
            #[cfg(not(unix))]
            let owner = None;
            return Ok(Destination {
                path,
                permissions: Some(meta.permissions()),
                owner,
            });
        }
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("is {}, not a regular file", kind_name(&kind)),
        ));
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("more than {MAX_LINKS} symbolic links in a row"),
    ))
}

/// What a file that is not a regular file is, with its article.
fn kind_name(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_fifo() {
            return "a named pipe";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a directory"
    } else {
        "something else"
    }
}

/// An empty temporary file beside `destination`, named `{prefix}*{suffix}`, with the
/// permissions the destination has, or a new file's (the usual ones less the umask, not a
/// private temporary's owner-only ones). Dropped, it is removed.
pub fn temp_beside(
    destination: &Destination,
    prefix: &str,
    suffix: &str,
) -> io::Result<NamedTempFile> {
    let dir = match destination.path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(prefix).suffix(suffix);
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let temp = tracked(|| builder.tempfile_in(dir), |t| t.path())?;
    // The owner first: changing it may clear the set-id bits the permissions then restore.
    // Only root may give a file away; anyone else's replacement is their own, as an editor's.
    #[cfg(unix)]
    if let Some((uid, gid)) = destination.owner {
        match std::os::unix::fs::fchown(temp.as_file(), Some(uid), Some(gid)) {
            Err(e) if e.kind() != io::ErrorKind::PermissionDenied => return Err(e),
            _ => {}
        }
    }
    if let Some(permissions) = &destination.permissions {
        temp.as_file().set_permissions(permissions.clone())?;
    }
    Ok(temp)
}

/// A destination replaced by [`commit_all`], and what it held before.
struct Replaced {
    /// The destination.
    path: PathBuf,
    /// A copy of the file it held; `None` when it held none.
    backup: Option<tempfile::TempPath>,
}

/// Puts every staged file in place, or none: when one cannot be put in place, those put before
/// it are taken back (the files they replaced restored). On failure, returns the destination
/// that failed with the error.
pub fn commit_all(files: Vec<StagedFile>) -> Result<(), (PathBuf, io::Error)> {
    let mut done: Vec<Replaced> = Vec::with_capacity(files.len());
    for file in files {
        let path = file.path.clone();
        let result = keep_copy(&path).and_then(|backup| file.commit().map(|()| backup));
        match result {
            Ok(backup) => done.push(Replaced { path, backup }),
            Err(error) => {
                for replaced in done.into_iter().rev() {
                    let _ = match replaced.backup {
                        Some(backup) => backup.persist(&replaced.path).map_err(|e| e.error),
                        None => std::fs::remove_file(&replaced.path),
                    };
                }
                return Err((path, error));
            }
        }
    }
    // Dropping the copies removes them.
    Ok(())
}

/// A copy of the file at `path`, if there is one, under a temporary name beside it, removed when
/// dropped.
fn keep_copy(path: &Path) -> io::Result<Option<tempfile::TempPath>> {
    if !path.is_file() {
        return Ok(None);
    }
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let mut backup = tracked(
        || {
            tempfile::Builder::new()
                .prefix(".modal-previous-")
                .suffix(".tmp")
                .tempfile_in(dir)
        },
        |t| t.path(),
    )?;
    // Through the file already open, never by its name: a signal that removed it meanwhile
    // must not see it made again.
    let mut source = std::fs::File::open(path)?;
    io::copy(&mut source, backup.as_file_mut())?;
    backup
        .as_file()
        .set_permissions(source.metadata()?.permissions())?;
    Ok(Some(backup.into_temp_path()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_changes_until_the_commit_and_a_drop_leaves_no_trace() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        std::fs::write(&path, "old").unwrap();
        let staged = StagedFile::write(&path, "test", b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        drop(staged);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        StagedFile::write(&path, "test", b"new")
            .unwrap()
            .commit()
            .unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_failed_commit_puts_back_every_file_committed_before_it() {
        let dir = tempfile::tempdir().unwrap();
        let (kept, new) = (dir.path().join("kept.txt"), dir.path().join("new.txt"));
        std::fs::write(&kept, "old").unwrap();
        // A destination that became a directory after it was staged cannot be replaced by a
        // file (one that is a directory already is refused when staged).
        let blocked = dir.path().join("blocked");
        let files = vec![
            StagedFile::write(&kept, "test", b"new").unwrap(),
            StagedFile::write(&new, "test", b"new").unwrap(),
            StagedFile::write(&blocked, "test", b"new").unwrap(),
        ];
        std::fs::create_dir(&blocked).unwrap();
        assert!(StagedFile::write(&blocked, "test", b"new")
            .unwrap_err()
            .to_string()
            .contains("is a directory"));
        let (failed, _) = commit_all(files).unwrap_err();
        assert_eq!(failed, blocked);
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "old");
        assert!(!new.exists());
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["blocked", "kept.txt"]);

        let files = vec![
            StagedFile::write(&kept, "test", b"new").unwrap(),
            StagedFile::write(&new, "test", b"new").unwrap(),
        ];
        commit_all(files).unwrap();
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "new");
        assert_eq!(std::fs::read_to_string(&new).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
    }
}
