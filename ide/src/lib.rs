//! The editor features of hstl specs, apart from any editor protocol (as typst keeps
//! `typst-ide` apart from its server): byte offsets in, plain data out. `hstlc lsp`
//! converts positions in the client's encoding to offsets and these answers to the
//! Language Server Protocol's types; this crate knows nothing of LSP or JSON-RPC.
//!
//! - [`analysis`]: one version of a document, parsed and checked (each spec against the
//!   world it names), and the index of every name written in it.
//! - [`worlds`]: the worlds documents name, read once and again when their file changes.
//! - [`hover`](mod@hover): what a name, an operator, a `world` item or `preset` means.
//! - [`navigate`]: definition, references and the outline.
//! - [`complete`]: completion, keywords and names.

pub mod analysis;
pub mod complete;
pub mod hover;
pub mod navigate;
pub mod worlds;

pub use analysis::{Analysis, Leftovers, Occurrence, SymKind, Symbol};
pub use complete::{Completion, CompletionKind, completion};
pub use hover::hover;
pub use navigate::{Outline, OutlineKind, Target, definition, references, symbols};
pub use worlds::{DocWorlds, WorldCache};
