//! `.fmu` unpacking: cache reuse and invalidation, zip-slip rejection, and broken archives
//! reported with the archive's name.

use std::io::Write;
use std::path::{Path, PathBuf};

use agrisim_cosim::archive::{fnv1a64, FmuArchive, PLATFORM};

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
    let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, data) in entries {
        z.start_file(*name, opts).unwrap();
        z.write_all(data).unwrap();
    }
    z.finish().unwrap();
}

/// Writes a minimal valid FMU (description and a stand-in binary) followed by `extra` entries.
fn minimal_fmu(path: &Path, extra: &[(&str, &[u8])]) {
    let lib = lib_entry();
    let mut entries: Vec<(&str, &[u8])> = vec![("modelDescription.xml", MD.as_bytes()), (&lib, b"x")];
    entries.extend_from_slice(extra);
    write_zip(path, &entries);
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
    assert_eq!(std::fs::read_to_string(a.resources_dir.join("lift.toml")).unwrap(), "height = 1.0");
    assert!(a.dir.join("modelDescription.xml").is_file());
    // No temporary directories left behind.
    let names: Vec<String> =
        std::fs::read_dir(&cache).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

#[test]
fn resources_dir_exists_even_when_the_archive_has_none() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("Lift.fmu");
    minimal_fmu(&fmu, &[]);
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
    write_zip(&fmu, &[("modelDescription.xml", MD.as_bytes()), (&lib_entry(), b"rebuilt")]);
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
    assert!(s.starts_with(&format!("FMU archive '{}': ", fmu.display())), "{s}");
    assert!(s.contains(expected), "error {s:?} does not contain {expected:?}");
}

/// Every file under `dir`, relative to it.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = vec![];
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(files_under(&p).into_iter().map(|f| Path::new(p.file_name().unwrap()).join(f)));
        } else {
            out.push(p.strip_prefix(dir).unwrap().to_path_buf());
        }
    }
    out
}

#[test]
fn zip_slip_entries_are_rejected_and_nothing_escapes() {
    let tmp = tempfile::tempdir().unwrap();
    // An absolute name pointing into this test's own directory, so a write would be seen.
    let absolute = tmp.path().join("abs-evil.txt").to_str().unwrap().to_string();
    let cases = [
        ("../evil.txt", "would be written outside the FMU directory"),
        ("resources/../../evil.txt", "would be written outside the FMU directory"),
        ("..\\evil.txt", "would be written outside the FMU directory"),
        (absolute.as_str(), "has an absolute path"),
        ("/evil.txt", "has an absolute path"),
        ("C:/evil.txt", "has an absolute path"),
    ];
    for (i, (evil, why)) in cases.into_iter().enumerate() {
        let work = tmp.path().join(format!("case{i}"));
        std::fs::create_dir_all(&work).unwrap();
        let fmu = work.join("Evil.fmu");
        // The bad entry comes after good ones, so extraction has started when it is met.
        minimal_fmu(&fmu, &[(evil, b"pwned")]);
        let cache = work.join("sub").join("cache");
        assert_import_err(&fmu, &cache, &format!("archive entry '{evil}' {why}"));
        // Nothing outside the cache (only the archive itself) and nothing half-extracted in it.
        assert_eq!(files_under(&work), [PathBuf::from("Evil.fmu")], "{evil}");
        assert!(!Path::new(&absolute).exists());
        assert!(std::fs::read_dir(&cache).unwrap().next().is_none(), "{evil}");
    }
}

#[test]
fn dot_dot_that_stays_inside_is_unpacked_where_it_resolves() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("Lift.fmu");
    minimal_fmu(&fmu, &[("resources/tmp/../lift.toml", b"height = 2.0")]);
    let a = FmuArchive::open(&fmu, &tmp.path().join("cache")).unwrap();
    assert_eq!(std::fs::read_to_string(a.resources_dir.join("lift.toml")).unwrap(), "height = 2.0");
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
    let at = damaged.windows(b"modelDescription.xml".len()).position(|w| w == b"modelDescription.xml").unwrap();
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
    assert_import_err(&fmu, &tmp.path().join("cache"), "no modelDescription.xml at the archive root");
}

#[test]
fn invalid_model_description_names_the_entry() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("Fmi1.fmu");
    let md = MD.replace(r#"fmiVersion="3.0""#, r#"fmiVersion="1.0""#);
    write_zip(&fmu, &[("modelDescription.xml", md.as_bytes()), (&lib_entry(), b"x")]);
    assert_import_err(
        &fmu,
        &tmp.path().join("cache"),
        &format!("{}!modelDescription.xml: fmiVersion is \"1.0\", only FMI 2.0 and 3.0", fmu.display()),
    );
}

#[test]
fn missing_binary_lists_the_platforms_present() {
    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join("WinOnly.fmu");
    write_zip(&fmu, &[("modelDescription.xml", MD.as_bytes()), ("binaries/x86_64-windows/agrisim_lift.dll", b"MZ")]);
    assert_import_err(
        &fmu,
        &tmp.path().join("cache"),
        &format!("no binary for this platform: binaries/{PLATFORM}/agrisim_lift.so is missing (platforms in archive: x86_64-windows)"),
    );

    let fmu = tmp.path().join("WrongName.fmu");
    write_zip(&fmu, &[("modelDescription.xml", MD.as_bytes()), (&format!("binaries/{PLATFORM}/lift.so"), b"x")]);
    assert_import_err(&fmu, &tmp.path().join("cache"), &format!("binaries/{PLATFORM}/agrisim_lift.so is missing"));
}
