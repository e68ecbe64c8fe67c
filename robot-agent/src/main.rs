//! `robot-agent`: one robot's process.

fn main() {
    println!("robot-agent: not yet implemented");
}
