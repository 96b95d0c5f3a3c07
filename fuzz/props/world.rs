//! World files (TOML) on any bytes, as `--world FILE.toml` reads them: never a panic; an
//! error names a byte range inside the text (on character boundaries), has a help and no
//! trailing period; an accepted world has a free cell, a slip in [0, 1], states that are
//! its free cells, and reads back as itself from its `params` (what `policy.json` keeps)
//! and from its own map lines.
use hstl::runtime::Env;
use hstl::world::GridWorld;

/// The property; panics when it fails.
pub fn check(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match GridWorld::from_toml(text, "fuzz") {
        Ok(world) => {
            assert!(world.num_states() >= 1);
            assert!(world.num_states() <= world.width() * world.height());
            assert!((0.0..=1.0).contains(&world.slip()));
            assert!(!world.starts().is_empty());
            let again = GridWorld::from_params(world.name(), &world.params())
                .expect("a world reads back from its params");
            assert_eq!(again, world);
            let lines = world.map_lines();
            assert_eq!(lines.len(), world.height());
            assert!(lines.iter().all(|l| l.chars().count() == world.width()));
        }
        Err(e) => {
            assert!(!e.message.is_empty() && !e.message.ends_with('.'), "{}", e.message);
            assert!(!e.help.is_empty() && !e.help.ends_with('.'), "{}", e.help);
            if let Some(span) = &e.span {
                assert!(span.start <= span.end && span.end <= text.len(), "{span:?}");
                assert!(text.is_char_boundary(span.start) && text.is_char_boundary(span.end));
            }
        }
    }
}
