//! intel_tex_2's prebuilt archives hold C++ objects (its ASTC kernel) that need the C++
//! runtime's exception personality; the crate does not link it itself.
fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    let env = std::env::var("CARGO_CFG_TARGET_ENV").unwrap_or_default();
    match (os.as_str(), env.as_str()) {
        ("macos" | "ios", _) => println!("cargo:rustc-link-lib=c++"),
        (_, "msvc") => {}
        _ => println!("cargo:rustc-link-lib=stdc++"),
    }
}
