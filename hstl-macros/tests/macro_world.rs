//! A spec that names its world through the macro: the item is accepted as Rust tokens (a
//! string literal), kept as `WORLD`, and changes nothing else of the generated spec.

use hstl::hstl;

hstl! {
    /// Two rooms of `four-rooms`.
    spec Rooms {
        world "four-rooms";
        state { x: int in 0..=12, y: int in 0..=12 }
        let A = x < 3 && y > 9;
        let B = x > 8 && y < 3;
        task always[0..] (eventually[0..45] A && eventually[0..45] B);
        option A;
        option B;
    }

    /// The same spec without the item.
    spec Same {
        state { x: int in 0..=12, y: int in 0..=12 }
        let A = x < 3 && y > 9;
        let B = x > 8 && y < 3;
        task always[0..] (eventually[0..45] A && eventually[0..45] B);
        option A;
        option B;
    }
}

#[test]
fn the_world_item_is_kept_and_changes_nothing_else() {
    use hstl::runtime::Spec;
    assert_eq!(rooms::WORLD, Some("four-rooms"));
    assert_eq!(same::WORLD, None);
    let (a, b) = (rooms::Rooms.task_spec(), same::Same.task_spec());
    assert_eq!(a.regions, b.regions);
    assert_eq!(a.options.len(), b.options.len());
    assert_eq!(a.learn, b.learn);
}
