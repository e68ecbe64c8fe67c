//! `supervisor-gen` command line.

fn main() {
    println!("supervisor-gen: not yet implemented");
}
