//! supervisor-gen's integration tests in one binary (one link instead of one per file).

mod algo_codegen;
mod algo_compiled;
mod algo_pipeline;
mod algo_props;
mod algo_reduce;
mod algo_textbook;
mod cli_reduce;
mod cli_synth;
mod validate_rules;
mod xml_robustness;
mod xml_roundtrip;
