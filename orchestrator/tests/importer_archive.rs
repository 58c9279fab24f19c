//! `.fmu` unpacking: cache reuse and invalidation, zip-slip rejection, and broken archives
//! reported with the archive's name.

use std::io::Write;
use std::path::{Path, PathBuf};

use agrisim::archive::{fnv1a64, FmuArchive, PLATFORM};

const MD: &str = r#"<fmiModelDescription fmiVersion="3.0" modelName="Lift" instantiationToken="{lift}">
  <CoSimulation modelIdentifier="agrisim_lift"/>
  <ModelVariables><Float64 name="h" valueReference="1" causality="output"/></ModelVariables>
</fmiModelDescription>"#;

fn lib_entry() -> String {
    format!("binaries/{PLATFORM}/agrisim_lift.so")
}

/// Writes a zip with the given (name, bytes) entries.
fn write_zip(path: &Path, entries: &[(&str, &[u8])]) {
    let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    for (name, data) in entries {
        z.start_file(*name, opts).unwrap();
        z.write_all(data).unwrap();
    }
    z.finish().unwrap();
}

fn good_fmu(dir: &Path) -> PathBuf {
    let p = dir.join("Lift.fmu");
    write_zip(
        &p,
        &[
            ("modelDescription.xml", MD.as_bytes()),
            (&lib_entry(), b"not really ELF"),
            ("resources/lift.toml", b"height = 1.0"),
            ("documentation/index.html", b"<p>lift</p>"),
        ],
    );
    p
}

#[test]
fn opens_and_exposes_paths() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = good_fmu(tmp.path());
    let cache = tmp.path().join("cache");
    let a = FmuArchive::open(&fmu, &cache).unwrap();
    assert_eq!(a.path, fmu);
    assert_eq!(a.md.model_name, "Lift");
    let hash = fnv1a64(&std::fs::read(&fmu).unwrap());
    assert_eq!(a.dir, cache.join(format!("agrisim_lift-{hash:016x}")));
    assert_eq!(a.library_path, a.dir.join(lib_entry()));
    assert_eq!(std::fs::read(&a.library_path).unwrap(), b"not really ELF");
    assert_eq!(a.resources_dir, a.dir.join("resources"));
    assert_eq!(
        std::fs::read_to_string(a.resources_dir.join("lift.toml")).unwrap(),
        "height = 1.0"
    );
    assert!(a.dir.join("modelDescription.xml").is_file());
    // No temporary directories left behind.
    let names: Vec<String> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

#[test]
fn resources_dir_exists_even_when_the_archive_has_none() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("Lift.fmu");
    write_zip(
        &fmu,
        &[
            ("modelDescription.xml", MD.as_bytes()),
            (&lib_entry(), b"x"),
        ],
    );
    let a = FmuArchive::open(&fmu, &tmp.path().join("cache")).unwrap();
    assert!(a.resources_dir.is_dir());
}

#[test]
fn complete_cache_is_reused_and_new_bytes_get_a_new_dir() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = good_fmu(tmp.path());
    let cache = tmp.path().join("cache");
    let a = FmuArchive::open(&fmu, &cache).unwrap();
    // A file that only exists in the cache proves the second open did not re-extract.
    std::fs::write(a.dir.join("sentinel"), b"1").unwrap();
    let b = FmuArchive::open(&fmu, &cache).unwrap();
    assert_eq!(a.dir, b.dir);
    assert!(b.dir.join("sentinel").is_file());

    // Rebuilt FMU (different bytes): a different directory.
    write_zip(
        &fmu,
        &[
            ("modelDescription.xml", MD.as_bytes()),
            (&lib_entry(), b"rebuilt"),
        ],
    );
    let c = FmuArchive::open(&fmu, &cache).unwrap();
    assert_ne!(c.dir, a.dir);
    assert_eq!(std::fs::read(&c.library_path).unwrap(), b"rebuilt");
}

#[test]
fn incomplete_cache_dir_is_replaced() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = good_fmu(tmp.path());
    let cache = tmp.path().join("cache");
    let a = FmuArchive::open(&fmu, &cache).unwrap();
    // Simulate a crash mid-extraction: no marker, library missing.
    for e in std::fs::read_dir(&a.dir).unwrap() {
        let p = e.unwrap().path();
        if p.file_name().unwrap().to_string_lossy().starts_with('.') {
            std::fs::remove_file(&p).unwrap();
        }
    }
    std::fs::remove_file(&a.library_path).unwrap();
    let b = FmuArchive::open(&fmu, &cache).unwrap();
    assert_eq!(b.dir, a.dir);
    assert!(b.library_path.is_file());
}

#[track_caller]
fn assert_import_err(fmu: &Path, cache: &Path, expected: &str) {
    let e = FmuArchive::open(fmu, cache).unwrap_err();
    assert_eq!(e.fmu, fmu);
    let s = e.to_string();
    assert!(
        s.starts_with(&format!("FMU archive '{}': ", fmu.display())),
        "{s}"
    );
    assert!(
        s.contains(expected),
        "error {s:?} does not contain {expected:?}"
    );
}

#[test]
fn zip_slip_entries_are_rejected_and_nothing_escapes() {
    for evil in [
        "../evil.txt",
        "resources/../../evil.txt",
        "/tmp/agrisim-evil.txt",
        "..\\evil.txt",
    ] {
        let tmp = tempfile::tempdir().unwrap();
        let fmu = tmp.path().join("Evil.fmu");
        write_zip(
            &fmu,
            &[
                ("modelDescription.xml", MD.as_bytes()),
                (&lib_entry(), b"x"),
                (evil, b"pwned"),
            ],
        );
        let cache = tmp.path().join("sub").join("cache");
        assert_import_err(
            &fmu,
            &cache,
            &format!("archive entry '{evil}' would be written outside the FMU directory"),
        );
        assert!(!tmp.path().join("sub").join("evil.txt").exists());
        assert!(!tmp.path().join("evil.txt").exists());
        assert!(!Path::new("/tmp/agrisim-evil.txt").exists());
        // Nothing half-extracted stays in the cache.
        let left: Vec<_> = std::fs::read_dir(&cache).unwrap().collect();
        assert!(left.is_empty(), "{left:?}");
    }
}

#[test]
fn corrupt_or_non_zip_file_is_rejected() {
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let fmu = tmp.path().join("Garbage.fmu");
    std::fs::write(&fmu, b"this is not a zip file at all").unwrap();
    assert_import_err(&fmu, &cache, "not a valid zip archive");

    // A real archive cut in half.
    let good = good_fmu(tmp.path());
    let bytes = std::fs::read(&good).unwrap();
    let cut = tmp.path().join("Truncated.fmu");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    assert_import_err(&cut, &cache, "not a valid zip archive");

    // Central directory intact, compressed data of an entry damaged.
    let mut damaged = bytes.clone();
    let at = damaged
        .windows(b"modelDescription.xml".len())
        .position(|w| w == b"modelDescription.xml")
        .unwrap();
    for b in &mut damaged[at + 40..at + 80] {
        *b ^= 0x5a;
    }
    let bad = tmp.path().join("Damaged.fmu");
    std::fs::write(&bad, &damaged).unwrap();
    let e = FmuArchive::open(&bad, &cache).unwrap_err();
    assert_eq!(e.fmu, bad);
}

#[test]
fn missing_file_is_rejected() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("Nope.fmu");
    assert_import_err(&fmu, &tmp.path().join("cache"), "cannot read");
}

#[test]
fn missing_model_description_is_rejected() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("NoMd.fmu");
    write_zip(&fmu, &[(&lib_entry(), b"x")]);
    assert_import_err(
        &fmu,
        &tmp.path().join("cache"),
        "no modelDescription.xml at the archive root",
    );
}

#[test]
fn invalid_model_description_names_the_entry() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("Fmi2.fmu");
    let md = MD.replace(r#"fmiVersion="3.0""#, r#"fmiVersion="2.0""#);
    write_zip(
        &fmu,
        &[
            ("modelDescription.xml", md.as_bytes()),
            (&lib_entry(), b"x"),
        ],
    );
    assert_import_err(
        &fmu,
        &tmp.path().join("cache"),
        &format!(
            "{}!modelDescription.xml: fmiVersion is \"2.0\"",
            fmu.display()
        ),
    );
}

#[test]
fn missing_binary_lists_the_platforms_present() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("WinOnly.fmu");
    write_zip(
        &fmu,
        &[
            ("modelDescription.xml", MD.as_bytes()),
            ("binaries/x86_64-windows/agrisim_lift.dll", b"MZ"),
        ],
    );
    assert_import_err(
        &fmu,
        &tmp.path().join("cache"),
        &format!("no binary for this platform: binaries/{PLATFORM}/agrisim_lift.so is missing (platforms in archive: x86_64-windows)"),
    );

    let fmu = tmp.path().join("WrongName.fmu");
    write_zip(
        &fmu,
        &[
            ("modelDescription.xml", MD.as_bytes()),
            (&format!("binaries/{PLATFORM}/lift.so"), b"x"),
        ],
    );
    assert_import_err(
        &fmu,
        &tmp.path().join("cache"),
        &format!("binaries/{PLATFORM}/agrisim_lift.so is missing"),
    );
}
