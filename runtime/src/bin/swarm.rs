//! `swarm`: launches and supervises experiments.

fn main() {
    println!("swarm: not yet implemented");
}
