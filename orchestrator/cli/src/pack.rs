//! `agrisim fmu pack`: turns every built FMU library into .fmu archives.
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

/// FMU libraries among the shared libraries in `dir` (those exporting the agrisim symbol).
pub fn find_fmu_libraries(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut libs = vec![];
    for entry in std::fs::read_dir(dir).context(|| format!("cannot list {}", dir.display()))? {
        let path = entry.context(|| format!("cannot list {}", dir.display()))?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with("libagrisim_fmu_") && name.ends_with(".so") {
            libs.push(path);
        }
    }
    libs.sort();
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
/// `out_dir/fmi2/<Id>.fmu`.
pub fn pack_library(library: &Path, out_dir: &Path) -> Result<Packed> {
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

/// Packs every FMU library found in `lib_dir`.
pub fn pack_all(lib_dir: &Path, out_dir: &Path) -> Result<Vec<Packed>> {
    let libs = find_fmu_libraries(lib_dir)?;
    if libs.is_empty() {
        return Err(agrisim_error::err!(
            "no FMU libraries (libagrisim_fmu_*.so) in {}: run `cargo build --release` first",
            lib_dir.display()
        ));
    }
    libs.iter().map(|l| pack_library(l, out_dir)).collect()
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
