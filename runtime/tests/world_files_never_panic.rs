//! Reading a world file never panics and every error's span lies inside the file: random
//! bytes and character-level mutations of the example worlds. `PROPTEST_CASES` overrides
//! the case count of each property (default 1,000).

use proptest::prelude::*;

use hstl_runtime::GridWorld;

const WORLDS: [&str; 3] = [
    include_str!("../../examples/worlds/four-rooms.toml"),
    include_str!("../../examples/worlds/corridors.toml"),
    include_str!("../../examples/worlds/warehouse.toml"),
];

/// Characters worth inserting: the map's own, TOML's quoting, and a few others.
const VOCAB: [&str; 16] = [
    "#", ".", "S", "\n", "\r\n", "\"", "'''", "\"\"\"", "=", " ", "\\", "x", "é", "\t", "0.5",
    "[x]",
];

fn check(text: &str) {
    match GridWorld::from_toml(text, "fuzz") {
        Ok(world) => {
            assert!(world.width() * world.height() > 0);
            assert!(!world.starts().is_empty());
        }
        Err(e) => {
            assert!(!e.message.is_empty() && !e.message.ends_with('.'), "{e:?}");
            assert!(!e.help.is_empty(), "{e:?}");
            if let Some(span) = &e.span {
                assert!(
                    span.start <= span.end && span.end <= text.len(),
                    "{span:?} in {}",
                    text.len()
                );
                assert!(text.is_char_boundary(span.start) && text.is_char_boundary(span.end));
            }
        }
    }
}

fn config() -> ProptestConfig {
    ProptestConfig { failure_persistence: None, ..ProptestConfig::default() }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn random_text_never_panics(text in ".{0,300}") {
        check(&text);
    }

    #[test]
    fn mutated_worlds_never_panic(
        world in 0..WORLDS.len(),
        edits in proptest::collection::vec((any::<usize>(), 0..VOCAB.len(), any::<bool>()), 1..8),
    ) {
        let mut chars: Vec<String> = WORLDS[world].chars().map(String::from).collect();
        for (at, word, insert) in edits {
            let i = at % (chars.len() + 1);
            if insert || i == chars.len() {
                chars.insert(i, VOCAB[word].to_string());
            } else {
                chars.remove(i);
            }
        }
        check(&chars.concat());
    }
}

#[test]
fn huge_maps_are_refused_before_they_are_built() {
    // 2,000 x 2,000 cells: past the limit, refused with the size.
    let row = ".".repeat(2000);
    let text = format!("map = '''\n{}'''\n", format!("{row}\n").repeat(2000));
    let e = GridWorld::from_toml(&text, "huge").unwrap_err();
    assert!(e.message.contains("2000 x 2000"), "{}", e.message);
}
