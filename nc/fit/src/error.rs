//! Why a rewrite stopped.

use nc_geom::segment::BuildError;
use nc_lang::ParseError;

/// Why the rewrite stopped. Nothing it wrote should be kept.
#[derive(Debug, thiserror::Error)]
pub enum RewriteError {
    #[error("{0}")]
    Parse(ParseError),
    #[error("{0}")]
    Build(BuildError),
    #[error("the fitted program does not parse: {0}")]
    OutputParse(ParseError),
    #[error("the fitted program does not build: {0}")]
    OutputBuild(BuildError),
    #[error("the fitted program has more or fewer motion blocks than were written ({read} read where {expected} were written)")]
    OutputBlocks { expected: usize, read: usize },
    #[error("cannot write the fitted program: {0}")]
    Write(#[from] std::io::Error),
}
