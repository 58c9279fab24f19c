//! An `.fmu` archive unpacked into a content-addressed cache directory.
//!
//! The cache directory name carries a hash of the archive bytes, so a rebuilt FMU never reuses
//! a stale unpacked copy, while repeated runs (benchmarks: thousands of trials) unzip once.
//! Extraction goes to a temporary sibling directory that is renamed into place only after a
//! completion marker is written, so a crash mid-extraction never leaves a half cache that
//! looks complete.

use std::fmt;
use std::io::{Cursor, Read};
use std::path::{Path, PathBuf};

use crate::model_description::ModelDescription;

/// FMI platform tuple of the binaries this build of the orchestrator loads.
pub const PLATFORM: &str = if cfg!(all(target_arch = "x86_64", target_os = "linux")) {
    "x86_64-linux"
} else if cfg!(all(target_arch = "aarch64", target_os = "linux")) {
    "aarch64-linux"
} else if cfg!(all(target_arch = "aarch64", target_os = "macos")) {
    "aarch64-darwin"
} else if cfg!(all(target_arch = "x86_64", target_os = "macos")) {
    "x86_64-darwin"
} else {
    "x86_64-windows"
};

/// The FMI 2.0 name of the same platform (`binaries/linux64`, ...).
pub const PLATFORM_FMI2: &str = if cfg!(all(target_arch = "x86_64", target_os = "linux")) {
    "linux64"
} else if cfg!(target_os = "linux") {
    "linux32"
} else if cfg!(target_os = "macos") {
    "darwin64"
} else {
    "win64"
};

/// Shared-library file extension on this platform.
const LIB_EXT: &str = if cfg!(target_os = "macos") {
    "dylib"
} else if cfg!(target_os = "windows") {
    "dll"
} else {
    "so"
};

/// Written last into a cache directory; its presence means the extraction is complete.
const MARKER: &str = ".agrisim-extracted";

/// Why an `.fmu` could not be imported. Always names the archive.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportError {
    pub fmu: PathBuf,
    pub message: String,
}

impl ImportError {
    fn new(fmu: &Path, message: impl Into<String>) -> ImportError {
        ImportError { fmu: fmu.to_path_buf(), message: message.into() }
    }
}

impl fmt::Display for ImportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "FMU archive '{}': {}", self.fmu.display(), self.message)
    }
}

impl std::error::Error for ImportError {}

/// An unpacked, checked FMU: its description and where its binary and resources are.
#[derive(Clone, Debug)]
pub struct FmuArchive {
    /// The `.fmu` file this came from.
    pub path: PathBuf,
    /// The unpacked directory in the cache.
    pub dir: PathBuf,
    pub md: ModelDescription,
    /// `binaries/<platform>/<modelIdentifier>.<ext>` inside `dir`.
    pub library_path: PathBuf,
    /// `resources/` inside `dir` (created empty when the archive has none, so it always exists).
    pub resources_dir: PathBuf,
}

impl FmuArchive {
    /// Unpacks `fmu_path` under `cache_root` (or reuses a complete earlier unpacking of the same
    /// bytes) and checks it has a valid FMI 3.0 or 2.0 description and a binary for this
    /// platform.
    pub fn open(fmu_path: &Path, cache_root: &Path) -> Result<FmuArchive, ImportError> {
        let bytes = std::fs::read(fmu_path).map_err(|e| ImportError::new(fmu_path, format!("cannot read: {e}")))?;
        let mut zip = zip::ZipArchive::new(Cursor::new(&bytes[..]))
            .map_err(|e| ImportError::new(fmu_path, format!("not a valid zip archive: {e}")))?;

        // Parse the description straight from the archive first: a broken FMU fails before
        // anything is written to the cache, and the cache name can use the model identifier.
        let md_text = {
            let mut entry = zip
                .by_name("modelDescription.xml")
                .map_err(|_| ImportError::new(fmu_path, "no modelDescription.xml at the archive root"))?;
            let mut s = String::new();
            entry
                .read_to_string(&mut s)
                .map_err(|e| ImportError::new(fmu_path, format!("cannot read modelDescription.xml: {e}")))?;
            s
        };
        let origin = format!("{}!modelDescription.xml", fmu_path.display());
        let md = ModelDescription::parse(&md_text, &origin).map_err(|e| ImportError::new(fmu_path, e.to_string()))?;

        let stem = sanitize(&md.model_identifier);
        let dir = cache_root.join(format!("{stem}-{:016x}", fnv1a64(&bytes)));
        if !dir.join(MARKER).is_file() {
            extract(&mut zip, fmu_path, cache_root, &dir)?;
        }

        let platform = match md.version {
            crate::model_description::FmiVersion::V3 => PLATFORM,
            crate::model_description::FmiVersion::V2 => PLATFORM_FMI2,
        };
        let rel_lib = format!("binaries/{platform}/{}.{LIB_EXT}", md.model_identifier);
        let library_path = dir.join(&rel_lib);
        if !library_path.is_file() {
            let platforms = list_dir(&dir.join("binaries"));
            return Err(ImportError::new(
                fmu_path,
                format!(
                    "no binary for this platform: {rel_lib} is missing (platforms in archive: {})",
                    if platforms.is_empty() { "none".to_string() } else { platforms.join(", ") }
                ),
            ));
        }
        let resources_dir = dir.join("resources");
        Ok(FmuArchive { path: fmu_path.to_path_buf(), dir, md, library_path, resources_dir })
    }
}

/// Unpacks any archive of the FMI/SSP family (an `.ssp`) under `cache_root` with the same
/// checks as an FMU (no entry outside its directory), reusing a complete earlier unpacking of
/// the same bytes; returns the directory.
pub fn unpack(path: &Path, cache_root: &Path) -> Result<PathBuf, ImportError> {
    let bytes = std::fs::read(path).map_err(|e| ImportError::new(path, format!("cannot read: {e}")))?;
    let mut zip = zip::ZipArchive::new(Cursor::new(&bytes[..]))
        .map_err(|e| ImportError::new(path, format!("not a valid zip archive: {e}")))?;
    let stem = sanitize(&path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
    let dir = cache_root.join(format!("{stem}-{:016x}", fnv1a64(&bytes)));
    if !dir.join(MARKER).is_file() {
        extract(&mut zip, path, cache_root, &dir)?;
    }
    Ok(dir)
}

/// Extracts every entry into a temporary directory, then renames it to `dir`.
fn extract(
    zip: &mut zip::ZipArchive<Cursor<&[u8]>>,
    fmu_path: &Path,
    cache_root: &Path,
    dir: &Path,
) -> Result<(), ImportError> {
    let io_err = |what: &str, p: &Path, e: std::io::Error| {
        ImportError::new(fmu_path, format!("cannot {what} '{}': {e}", p.display()))
    };
    std::fs::create_dir_all(cache_root).map_err(|e| io_err("create cache directory", cache_root, e))?;
    let dir_name = dir.file_name().and_then(|n| n.to_str()).unwrap_or("fmu");
    // Unique per process and call, so concurrent extractions (threads or processes) never share it.
    static SEQ: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let seq = SEQ.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = cache_root.join(format!(".{dir_name}.tmp{}-{seq}", std::process::id()));
    if tmp.exists() {
        std::fs::remove_dir_all(&tmp).map_err(|e| io_err("remove", &tmp, e))?;
    }
    std::fs::create_dir_all(&tmp).map_err(|e| io_err("create", &tmp, e))?;

    let result = (|| {
        for i in 0..zip.len() {
            let mut entry =
                zip.by_index(i).map_err(|e| ImportError::new(fmu_path, format!("corrupt archive entry #{i}: {e}")))?;
            let name = entry
                .name()
                .map_err(|e| ImportError::new(fmu_path, format!("archive entry #{i} has an unreadable name: {e}")))?
                .into_owned();
            if has_root(&name) {
                return Err(ImportError::new(
                    fmu_path,
                    format!("archive entry '{name}' has an absolute path; refusing to unpack"),
                ));
            }
            let rel = entry.enclosed_name().ok_or_else(|| {
                ImportError::new(fmu_path, format!("archive entry '{name}' would be written outside the FMU directory (zip-slip); refusing to unpack"))
            })?;
            let out = tmp.join(&rel);
            if entry.is_dir() {
                std::fs::create_dir_all(&out).map_err(|e| io_err("create", &out, e))?;
                continue;
            }
            if let Some(parent) = out.parent() {
                std::fs::create_dir_all(parent).map_err(|e| io_err("create", parent, e))?;
            }
            let mut data = Vec::new();
            entry
                .read_to_end(&mut data)
                .map_err(|e| ImportError::new(fmu_path, format!("corrupt archive entry '{name}': {e}")))?;
            std::fs::write(&out, &data).map_err(|e| io_err("write", &out, e))?;
        }
        let res = tmp.join("resources");
        std::fs::create_dir_all(&res).map_err(|e| io_err("create", &res, e))?;
        let marker = tmp.join(MARKER);
        std::fs::write(&marker, b"complete\n").map_err(|e| io_err("write", &marker, e))?;
        // An incomplete directory (no marker) from an earlier crash is replaced.
        if dir.exists() && !dir.join(MARKER).is_file() {
            std::fs::remove_dir_all(dir).map_err(|e| io_err("remove stale", dir, e))?;
        }
        match std::fs::rename(&tmp, dir) {
            Ok(()) => Ok(()),
            // Another process finished the same extraction first: use theirs.
            Err(_) if dir.join(MARKER).is_file() => {
                let _ = std::fs::remove_dir_all(&tmp);
                Ok(())
            }
            Err(e) => Err(io_err("rename into place", dir, e)),
        }
    })();
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result
}

/// Whether an entry name starts at a root or drive (`/x`, `\\x`, `C:x`). `enclosed_name()`
/// refuses names that climb out with `..` but silently makes these relative (`/etc/x` ->
/// `etc/x`); an FMU never has them, so they are refused instead.
fn has_root(name: &str) -> bool {
    name.starts_with(['/', '\\']) || matches!(name.as_bytes(), [d, b':', ..] if d.is_ascii_alphabetic())
}

/// Keeps a name safe as one directory component.
fn sanitize(s: &str) -> String {
    s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect()
}

fn list_dir(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| rd.filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// FNV-1a, 64 bit: a small stable content hash for cache directory names (not cryptographic;
/// it only has to tell different builds of an FMU apart).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_known_values() {
        assert_eq!(fnv1a64(b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x85944171f73967e8);
    }
}
