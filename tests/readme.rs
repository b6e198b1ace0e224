//! The README's Rust quick start is `tests/snippets/readme_quickstart.rs`, a
//! whole `src/main.rs` with its dependency line, which the crate compiles and
//! runs as a doctest (see `src/lib.rs`). This test keeps the README's copy
//! identical to it, and the snippet a program as written: its own `main`
//! returning a `Result` (the `?` needs it) and the dependency line.

#[test]
fn readme_rust_block_is_the_compiled_snippet() {
    let root = env!("CARGO_MANIFEST_DIR");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).expect("README.md");
    let snippet = std::fs::read_to_string(format!("{root}/tests/snippets/readme_quickstart.rs"))
        .expect("snippet");
    let section = readme
        .split("## Quick start (Rust)")
        .nth(1)
        .expect("a Quick start (Rust) section");
    let block = section
        .split("```rust\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("a rust block");
    assert_eq!(
        block, snippet,
        "README's Rust block differs from the snippet"
    );
    assert!(snippet.contains("fn main() -> Result<(), Box<dyn std::error::Error>> {"));
    assert!(snippet.contains("adaptimp = { path = "));
}
