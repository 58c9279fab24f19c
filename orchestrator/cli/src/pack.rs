//! `agrisim fmu pack`: turns every built FMU library into .fmu archives.
//!
//! Which libraries are FMUs comes from the crates' Cargo.toml (`[package.metadata.agrisim]
//! fmu = "<Id>"`), embedded at compile time by build.rs ([`FMU_CRATES`]), never from file
//! names: a stale or unrelated library in the directory is not packed, and a marked crate
//! whose library is missing, or whose library names another model, is an error.
//!
//! The modelDescription.xml is not a file in the source tree: each FMU library generates it
//! from its own variable table (symbols `agrisim_model_description_fmi3/2`), so packing
//! dlopens the library, asks it, and zips XML + binary. Archives are deterministic (sorted
//! entries, fixed timestamps), so the same build gives byte-identical .fmu files.

use agrisim_cosim::model_description::ModelDescription;
use agrisim_error::{Context, Result};
use std::ffi::{c_char, CStr};
use std::io::Write;
use std::path::{Path, PathBuf};

/// One packed FMU.
#[derive(Debug, Clone)]
pub struct Packed {
    pub model_identifier: String,
    pub fmi3: PathBuf,
    /// FMI 2.0 archive, when the library exports an FMI 2 description.
    pub fmi2: Option<PathBuf>,
}

/// The XML a library generates for `symbol`, or None if it does not export it.
fn description(lib: &libloading::Library, symbol: &[u8]) -> Option<String> {
    // SAFETY: the symbol, when present, is `extern "C" fn() -> *const c_char` returning a
    // NUL-terminated static string (agrisim_fmi::export_fmu!).
    unsafe {
        let f = lib.get::<unsafe extern "C" fn() -> *const c_char>(symbol).ok()?;
        let p = f();
        if p.is_null() {
            return None;
        }
        Some(CStr::from_ptr(p).to_string_lossy().into_owned())
    }
}

/// A workspace crate marked as an FMU in its Cargo.toml.
#[derive(Debug, Clone, Copy)]
pub struct FmuCrate {
    /// Package name, for messages.
    pub package: &'static str,
    /// The cdylib's name (file `lib<library>.so`).
    pub library: &'static str,
    /// The marker: the modelIdentifier its modelDescription must name.
    pub fmu: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/fmu_crates.rs"));

impl FmuCrate {
    /// The shared library's file name on this platform.
    pub fn file_name(&self) -> String {
        format!("{}{}{}", std::env::consts::DLL_PREFIX, self.library, std::env::consts::DLL_SUFFIX)
    }
}

/// The library of every FMU crate in `dir`, with the crate; a missing one is an error that
/// names the crate.
pub fn find_fmu_libraries(dir: &Path) -> Result<Vec<(PathBuf, FmuCrate)>> {
    let mut libs = vec![];
    for c in FMU_CRATES {
        let path = dir.join(c.file_name());
        if !path.is_file() {
            return Err(agrisim_error::err!(
                "{} missing: crate {} (FMU {}) is not built; run `cargo build --release`",
                path.display(),
                c.package,
                c.fmu
            ));
        }
        libs.push((path, *c));
    }
    Ok(libs)
}

fn zip_fmu(out: &Path, xml: &str, binary_dir: &str, identifier: &str, library: &[u8]) -> Result<()> {
    write_zip(
        out,
        &[
            (format!("binaries/{binary_dir}/{identifier}.so"), library),
            ("modelDescription.xml".to_string(), xml.as_bytes()),
        ],
    )
}

/// A deterministic zip (entries in the given order, fixed timestamps), so the same inputs give
/// byte-identical archives.
fn write_zip(out: &Path, entries: &[(String, &[u8])]) -> Result<()> {
    use zip::write::SimpleFileOptions;
    let file = std::fs::File::create(out).context(|| format!("cannot create {}", out.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let opts = SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default())
        .unix_permissions(0o644);
    for (name, bytes) in entries {
        zip.start_file(name.as_str(), opts).context(|| format!("{}: {name}", out.display()))?;
        zip.write_all(bytes).context(|| format!("{}: {name}", out.display()))?;
    }
    zip.finish().context(|| format!("cannot finish {}", out.display()))?;
    Ok(())
}

/// Packs one library into `out_dir/<Id>.fmu` and, if it has an FMI 2 description,
/// `out_dir/fmi2/<Id>.fmu`. The modelIdentifier its description names must be `expected.fmu`.
pub fn pack_library(library: &Path, expected: &FmuCrate, out_dir: &Path) -> Result<Packed> {
    // SAFETY: loading our own FMU library; its initializers are Rust statics only.
    let lib = unsafe { libloading::Library::new(library) }.context(|| format!("cannot load {}", library.display()))?;
    let xml3 = description(&lib, b"agrisim_model_description_fmi3\0").ok_or_else(|| {
        agrisim_error::err!(
            "{} does not export agrisim_model_description_fmi3 (not built with export_fmu!)",
            library.display()
        )
    })?;
    let md = ModelDescription::parse(&xml3, &library.display().to_string())?;
    let id = md.model_identifier.clone();
    if id != expected.fmu {
        return Err(agrisim_error::err!(
            "{}: its modelDescription names modelIdentifier '{id}', but crate {} is marked fmu = \"{}\" \
             ([package.metadata.agrisim] in its Cargo.toml); make the two agree",
            library.display(),
            expected.package,
            expected.fmu
        ));
    }
    let bytes = std::fs::read(library).context(|| format!("cannot read {}", library.display()))?;
    std::fs::create_dir_all(out_dir).context(|| format!("cannot create {}", out_dir.display()))?;
    let fmi3 = out_dir.join(format!("{id}.fmu"));
    zip_fmu(&fmi3, &xml3, "x86_64-linux", &id, &bytes)?;
    let fmi2 = match description(&lib, b"agrisim_model_description_fmi2\0") {
        Some(xml2) => {
            let dir = out_dir.join("fmi2");
            std::fs::create_dir_all(&dir).context(|| format!("cannot create {}", dir.display()))?;
            let path = dir.join(format!("{id}.fmu"));
            zip_fmu(&path, &xml2, "linux64", &id, &bytes)?;
            Some(path)
        }
        None => None,
    };
    Ok(Packed { model_identifier: id, fmi3, fmi2 })
}

/// Packs the library of every FMU crate, found in `lib_dir`.
pub fn pack_all(lib_dir: &Path, out_dir: &Path) -> Result<Vec<Packed>> {
    find_fmu_libraries(lib_dir)?.iter().map(|(l, c)| pack_library(l, c, out_dir)).collect()
}

/// The subdirectory of the systems directory, of the packed-FMU directory and of the SSP
/// output directory that holds FMI 2.0 systems, FMUs and archives.
pub const FMI2_DIR: &str = "fmi2";

/// Packs every system: `systems_dir/*.ssd` with the FMI 3.0 archives of `fmu_dir` into
/// `out_dir/*.ssp`, and `systems_dir/fmi2/*.ssd` (when that directory exists) with the FMI 2.0
/// archives of `fmu_dir/fmi2` into `out_dir/fmi2/*.ssp`, for masters that import FMI 2.0 only.
pub fn pack_systems(systems_dir: &Path, fmu_dir: &Path, out_dir: &Path) -> Result<Vec<PathBuf>> {
    let mut written = pack_ssps(systems_dir, fmu_dir, out_dir)?;
    let fmi2 = systems_dir.join(FMI2_DIR);
    if fmi2.is_dir() {
        written.extend(pack_ssps(&fmi2, &fmu_dir.join(FMI2_DIR), &out_dir.join(FMI2_DIR))?);
    }
    Ok(written)
}

/// Writes `out_dir/<system>.ssp` for every `.ssd` in `systems_dir`: a self-contained SSP
/// archive (SystemStructure.ssd at the root, every component's FMU under resources/, sources
/// rewritten to point there) that other SSP tools and `agrisim run` load as they are.
pub fn pack_ssps(systems_dir: &Path, fmu_dir: &Path, out_dir: &Path) -> Result<Vec<PathBuf>> {
    use agrisim_cosim::ssp::{resolve_source, SystemStructure};
    let mut ssds: Vec<PathBuf> = std::fs::read_dir(systems_dir)
        .context(|| format!("cannot list {}", systems_dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "ssd"))
        .collect();
    ssds.sort();
    std::fs::create_dir_all(out_dir).context(|| format!("cannot create {}", out_dir.display()))?;
    let mut written = vec![];
    for ssd in ssds {
        let mut text = std::fs::read_to_string(&ssd).context(|| format!("cannot read {}", ssd.display()))?;
        let structure = SystemStructure::parse(&text, &ssd)?;
        let mut resources = std::collections::BTreeMap::new();
        for c in &structure.components {
            let path = resolve_source(&ssd, &c.source, fmu_dir);
            let file = path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
            let bytes = std::fs::read(&path).context(|| {
                format!(
                    "{}: component '{}': cannot read {} (run `agrisim fmu pack` after `cargo build --release`)",
                    ssd.display(),
                    c.name,
                    path.display()
                )
            })?;
            resources.insert(format!("resources/{file}"), bytes);
            let (old, new) = (format!("source=\"{}\"", c.source), format!("source=\"resources/{file}\""));
            // Components sharing one FMU (the two arms) were rewritten with the first.
            if !text.contains(&old) && !text.contains(&new) {
                return Err(agrisim_error::err!(
                    "{}: component '{}': cannot find {old} to rewrite",
                    ssd.display(),
                    c.name
                ));
            }
            text = text.replace(&old, &new);
        }
        let stem = ssd.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let out = out_dir.join(format!("{stem}.ssp"));
        let mut entries: Vec<(String, &[u8])> = vec![("SystemStructure.ssd".to_string(), text.as_bytes())];
        entries.extend(resources.iter().map(|(k, v)| (k.clone(), v.as_slice())));
        write_zip(&out, &entries)?;
        written.push(out);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn marked(package: &str) -> FmuCrate {
        *FMU_CRATES.iter().find(|c| c.package == package).unwrap_or_else(|| panic!("{package} is not in FMU_CRATES"))
    }

    #[test]
    fn build_script_embeds_the_marked_crates() {
        for (package, library, fmu) in [
            ("agrisim-fmu-chassis-kinematic", "agrisim_fmu_chassis_kinematic", "ChassisKinematic"),
            ("agrisim-fmu-greenhouse", "agrisim_fmu_greenhouse", "Greenhouse"),
            ("agrisim-fmu-testmodel", "agrisim_fmu_testmodel", "TestModel"),
        ] {
            let c = marked(package);
            assert_eq!((c.library, c.fmu), (library, fmu));
        }
        // Libraries are not FMUs, whatever their names.
        assert!(FMU_CRATES.iter().all(|c| !["agrisim-fmi", "agrisim-chassis", "agrisim-msgs"].contains(&c.package)));
        assert_eq!(marked("agrisim-fmu-lift").file_name(), "libagrisim_fmu_lift.so");
    }

    #[test]
    fn a_missing_library_names_its_crate() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let e = find_fmu_libraries(&dir).expect_err("no library is in src/").to_string();
        let first = FMU_CRATES[0];
        assert!(e.contains(&first.file_name()) && e.contains(first.package) && e.contains("cargo build"), "{e}");
    }

    #[test]
    fn a_library_naming_another_model_is_refused() {
        // target/release/deps/<this test> -> target/release, where the FMU libraries are built.
        let exe = std::env::current_exe().expect("test executable path");
        let dir = exe.parent().and_then(Path::parent).expect("target/<profile>/deps");
        let lift = marked("agrisim-fmu-lift");
        let library = dir.join(lift.file_name());
        assert!(library.is_file(), "{} missing: run `cargo build --release -p agrisim-fmu-lift`", library.display());
        let out = std::env::temp_dir().join(format!("agrisim-pack-test-{}", std::process::id()));
        let wrong = FmuCrate { fmu: "Arm", ..lift };
        let e = pack_library(&library, &wrong, &out).expect_err("Lift packed as Arm").to_string();
        assert!(e.contains("modelIdentifier 'Lift'") && e.contains("fmu = \"Arm\""), "{e}");
        assert!(!out.exists(), "nothing is written for a refused library");
        let packed = pack_library(&library, &lift, &out).expect("Lift packs as Lift");
        assert_eq!(packed.fmi3, out.join("Lift.fmu"));
        std::fs::remove_dir_all(&out).expect("remove the test's output");
    }

    #[test]
    fn a_model_exchange_only_library_packs_for_both_versions() {
        // The modelIdentifier comes from <ModelExchange> when there is no <CoSimulation>.
        let exe = std::env::current_exe().expect("test executable path");
        let dir = exe.parent().and_then(Path::parent).expect("target/<profile>/deps");
        let osc = marked("agrisim-fmu-oscillator");
        let library = dir.join(osc.file_name());
        assert!(
            library.is_file(),
            "{} missing: run `cargo build --release -p agrisim-fmu-oscillator`",
            library.display()
        );
        let out = std::env::temp_dir().join(format!("agrisim-pack-me-test-{}", std::process::id()));
        let packed = pack_library(&library, &osc, &out).expect("Oscillator packs");
        assert_eq!(packed.model_identifier, "Oscillator");
        for path in [Some(packed.fmi3), packed.fmi2].into_iter().flatten() {
            let file = std::fs::File::open(&path).expect("archive written");
            let mut zip = zip::ZipArchive::new(file).expect("a zip archive");
            let mut xml = String::new();
            std::io::Read::read_to_string(&mut zip.by_name("modelDescription.xml").expect("its XML"), &mut xml)
                .expect("UTF-8 XML");
            assert!(xml.contains("<ModelExchange modelIdentifier=\"Oscillator\"") && !xml.contains("<CoSimulation"));
        }
        std::fs::remove_dir_all(&out).expect("remove the test's output");
    }
}
