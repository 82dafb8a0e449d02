//! The committed C header is exactly what cbindgen (the pinned version) generates from
//! src/ffi with cbindgen.toml (`cbindgen --config cbindgen.toml src/ffi/mod.rs` with the
//! cbindgen binary of the same version gives the same file). `SHAPECORR_BLESS_HEADER=1` rewrites it instead.

use std::path::Path;

#[test]
fn committed_header_matches_the_code() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        // Only the FFI module: the rest of the crate's public items are not C API.
        .with_src(root.join("src/ffi/mod.rs"))
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let path = root.join("include/shapecorr.h");
    if std::env::var_os("SHAPECORR_BLESS_HEADER").is_some() {
        std::fs::write(&path, &generated).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/shapecorr.h differs from what cbindgen generates from src/ffi; regenerate it \
         with `SHAPECORR_BLESS_HEADER=1 cargo test --release --test it header::` and commit it"
    );
}
