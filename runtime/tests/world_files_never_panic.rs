//! Reading a world file never panics and every error's span lies inside the file: random
//! bytes and character-level mutations of the example worlds, grid and plane. A plane world
//! that reads resets and steps onto free positions only. `PROPTEST_CASES` overrides the case
//! count of each property (default 1,000).

use proptest::prelude::*;

use hstl_runtime::world::AnyWorld;
use hstl_runtime::{GridWorld, World, seeded_rng};

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

const PLANES: [&str; 2] = [include_str!("data/yard.toml"), include_str!("data/maze.toml")];

/// Plane worlds' own words and numbers, beside TOML's.
const PLANE_VOCAB: [&str; 24] = [
    "[", "]", "{", "}", ",", "=", "\"", "-", "0", "1", ".5", "e9", "inf", "nan", " ", "\n",
    "circle", "rect", "start", "kind", "\"grid\"", "x", "#", "é",
];

/// Reads `text` as any world; a plane world's runs stay on free positions.
fn check_any(text: &str) {
    match AnyWorld::from_toml(text, "fuzz") {
        Ok(AnyWorld::Plane(world)) => {
            let mut rng = seeded_rng(0);
            let mut s = world.reset(&mut rng);
            assert!(world.is_free(s), "{s:?}");
            for t in 0..20 {
                s = world.step(&s, t % world.headings(), &mut rng);
                assert!(world.is_free(s), "{s:?}");
            }
        }
        Ok(AnyWorld::Grid(_)) => {}
        Ok(AnyWorld::MountainCar(_)) => panic!("a world file made mountain-car: {text}"),
        Err(e) => check_error(text, &e),
    }
}

fn check_error(text: &str, e: &hstl_runtime::world::WorldError) {
    assert!(!e.message.is_empty() && !e.message.ends_with('.'), "{e:?}");
    assert!(!e.help.is_empty(), "{e:?}");
    if let Some(span) = &e.span {
        assert!(span.start <= span.end && span.end <= text.len(), "{span:?} in {}", text.len());
        assert!(text.is_char_boundary(span.start) && text.is_char_boundary(span.end));
    }
}

fn check(text: &str) {
    check_any(text);
    match GridWorld::from_toml(text, "fuzz") {
        Ok(world) => {
            assert!(world.width() * world.height() > 0);
            assert!(!world.starts().is_empty());
        }
        Err(e) => check_error(text, &e),
    }
}

/// Mostly numbers a world might hold, sometimes any double at all.
fn number() -> impl Strategy<Value = f64> {
    prop_oneof![3 => -50.0f64..50.0, 1 => 0.0f64..2.0, 1 => any::<f64>()]
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

    #[test]
    fn mutated_plane_worlds_never_panic(
        world in 0..PLANES.len(),
        edits in proptest::collection::vec((any::<usize>(), 0..PLANE_VOCAB.len(), any::<bool>()), 1..8),
    ) {
        let mut chars: Vec<String> = PLANES[world].chars().map(String::from).collect();
        for (at, word, insert) in edits {
            let i = at % (chars.len() + 1);
            if insert || i == chars.len() {
                chars.insert(i, PLANE_VOCAB[word].to_string());
            } else {
                chars.remove(i);
            }
        }
        check(&chars.concat());
    }

    #[test]
    fn random_plane_numbers_never_panic(
        x in (number(), number()), step in number(), headings in -5i64..80,
        slip in number(), noise in number(),
        circle in (number(), number(), number()),
        start in (number(), number(), number(), number()),
    ) {
        // Every number TOML can write, in every slot (NaN and infinities as `nan`, `inf`).
        let n = |v: f64| if v.is_nan() { "nan".to_string() } else if v.is_infinite() {
            if v > 0.0 { "inf".into() } else { "-inf".into() }
        } else { format!("{v:e}") };
        let text = format!(
            "kind = \"plane\"\nx = [{}, {}]\ny = [0, 10]\nstep = {}\nheadings = {headings}\n\
             slip = {}\nnoise = {}\nobstacles = [{{ circle = [{}, {}, {}] }}]\nstart = [{}, {}, {}, {}]\n",
            n(x.0), n(x.1), n(step), n(slip), n(noise), n(circle.0), n(circle.1), n(circle.2),
            n(start.0), n(start.1), n(start.2), n(start.3)
        );
        check_any(&text);
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
