//! What the jobs render with: SVG [`figures`], an episode's self-contained HTML
//! replay page ([`replay_html`]) and printed documents as text, Markdown or HTML
//! ([`Document`], [`Grid`]); each job builds its own report's document.
//!
//! The face of this part is what it re-exports here, and the [`figures`] module.

pub mod figures;
pub(crate) mod replay_page;
pub(crate) mod tables;

pub use replay_page::replay_html;
pub use tables::{Block, Document, Grid};
