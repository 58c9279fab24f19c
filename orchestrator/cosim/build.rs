//! Compiles the FMI 2.0 logger callback (variadic C; see src/fmi2/logger.c).
fn main() {
    println!("cargo:rerun-if-changed=src/fmi2/logger.c");
    cc::Build::new().file("src/fmi2/logger.c").warnings(true).compile("agrisim_fmi2_logger");
}
