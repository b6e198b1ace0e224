//! `include/adaptimp.h` is what cbindgen generates from `src/lib.rs` now.
//! Regenerate it with `ADAPTIMP_BLESS=1 cargo test -p adaptimp-ffi --test header`.

use std::path::Path;

#[test]
fn the_checked_in_header_is_fresh() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let path = dir.join("include/adaptimp.h");
    if std::env::var_os("ADAPTIMP_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let checked_in = std::fs::read(&path).unwrap_or_default();
    assert!(
        checked_in == generated,
        "include/adaptimp.h is stale: run ADAPTIMP_BLESS=1 cargo test -p adaptimp-ffi --test header"
    );
}
