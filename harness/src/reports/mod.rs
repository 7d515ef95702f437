//! What the jobs render with: SVG figures ([`figures`]), an episode's self-contained HTML
//! replay page ([`replay_page`]) and printed documents as text, Markdown or HTML
//! ([`tables`]); each job builds its own report's document.

pub mod figures;
pub mod replay_page;
pub mod tables;
