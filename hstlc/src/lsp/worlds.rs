//! The worlds of the language server's documents: `hstl-ide`'s cache, reading each world
//! as `hstlc check` does, and `file:` URIs to paths and back.

use std::path::{Path, PathBuf};

use hstl::lang::WorldProblem;
use hstl::world::Facts;
use hstl_ide::worlds::WorldCache;
use lsp_types::Uri;

use crate::world_arg::{LoadedWorld, item_help};

/// An empty cache of the worlds documents name, read as `hstlc check` reads them.
pub fn cache() -> WorldCache {
    WorldCache::new(load)
}

/// Reads the world `name` names as `hstlc check` does.
fn load(name: &str, folder: Option<&Path>) -> Result<(Facts, String), WorldProblem> {
    let world = LoadedWorld::named(name, folder)
        .map_err(|e| WorldProblem { message: e.to_string(), help: item_help(&e) })?;
    Ok((hstl::world::any_facts(&world.world, &world.label), world.words()))
}

/// The file a `file:` URI names, or `None` for another scheme.
pub fn uri_path(uri: &Uri) -> Option<PathBuf> {
    let s = uri.as_str();
    let rest = s.strip_prefix("file://")?;
    // `file:///path` or `file://localhost/path`.
    let rest = rest.strip_prefix("localhost").unwrap_or(rest);
    if !rest.starts_with('/') {
        return None;
    }
    let bytes = percent_decode(rest)?;
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStringExt;
        Some(PathBuf::from(std::ffi::OsString::from_vec(bytes)))
    }
    #[cfg(not(unix))]
    {
        String::from_utf8(bytes).ok().map(PathBuf::from)
    }
}

/// The `file:` URI of an absolute path.
pub fn path_uri(path: &Path) -> Option<Uri> {
    let path = std::path::absolute(path).ok()?;
    let text = path.to_str()?;
    let mut out = String::from("file://");
    for b in text.bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out.parse().ok()
}

fn percent_decode(s: &str) -> Option<Vec<u8>> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = s.get(i + 1..i + 3)?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    Some(out)
}
