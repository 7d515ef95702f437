//! What runs leave behind: result files written atomically ([`files`]), SVG figures
//! ([`figures`]), an episode's self-contained HTML replay page ([`replay_page`]) and the
//! printed tables of `compare`, `eval` and `batch` as text, Markdown or HTML ([`tables`]).

pub mod figures;
pub mod replay_page;
pub mod tables;
