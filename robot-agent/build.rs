//! Links `robot-agent` with its segments aligned to 2 MiB, so that its code starts on a huge-page boundary and the
//! zygote can move it onto transparent huge pages (`src/huge_text.rs`).

fn main() {
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!(
            "cargo:rustc-link-arg-bin=robot-agent=-Wl,-z,max-page-size=0x200000,-z,separate-code"
        );
    }
}
