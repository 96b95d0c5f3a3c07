//! Plane world files (`kind = "plane"`): every value read as it was written, so that each
//! error, of type, shape or range, points at the value it is about.

use std::fmt;
use std::ops::Range;

use serde::Deserialize;
use serde::de::{self, IgnoredAny, MapAccess, SeqAccess, Visitor};
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::{WorldError, world_name};
use crate::plane::{
    CIRCLE_HELP, ConfigError, EXTENT_HELP, Field, HEADINGS_HELP, MAX_OBSTACLES, NOISE_HELP,
    Obstacle, PlaneConfig, PlaneWorld, RECT_HELP, SLIP_HELP, START_HELP, STEP_HELP, num,
};

/// The keys of a plane world file, each value as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaneFile {
    name: Option<Spanned<Raw>>,
    kind: Option<Spanned<Raw>>,
    x: Option<Spanned<Raw>>,
    y: Option<Spanned<Raw>>,
    step: Option<Spanned<Raw>>,
    headings: Option<Spanned<Raw>>,
    slip: Option<Spanned<Raw>>,
    noise: Option<Spanned<Raw>>,
    obstacles: Option<Spanned<Raw>>,
    start: Option<Spanned<Raw>>,
}

const KEYS_HELP: &str = "a plane world file has only the keys `name`, `kind`, `x`, `y`, \
                         `step`, `headings`, `slip`, `noise`, `obstacles` and `start`";
const OBSTACLE_HELP: &str =
    "write each obstacle as `{ circle = [cx, cy, r] }` or `{ rect = [x0, y0, x1, y1] }`";
const OBSTACLES_HELP: &str = "write the obstacles as a list, such as \
                              `obstacles = [{ circle = [10.0, 5.0, 1.5] }, { rect = [4.0, 0.0, 5.0, 6.0] }]`";

/// The most items a list keeps; the rest are counted, not kept.
const MAX_ITEMS: usize = MAX_OBSTACLES;

/// A TOML value as written, lists and tables kept whole up to [`MAX_ITEMS`] entries.
enum Raw {
    Float(f64),
    Integer(i128),
    Str(String),
    /// The items kept and how many there were.
    List(Vec<Spanned<Raw>>, usize),
    /// The entries kept and how many there were.
    Table(Vec<(Spanned<String>, Spanned<Raw>)>, usize),
    /// A boolean (dates are refused before, see [`refuse_dates`]).
    Other(&'static str),
}

impl Raw {
    /// What kind of value this is, for messages.
    fn what(&self) -> &'static str {
        match self {
            Raw::Float(_) | Raw::Integer(_) => "a number",
            Raw::Str(_) => "a string",
            Raw::List(..) => "a list",
            Raw::Table(..) => "a table",
            Raw::Other(what) => what,
        }
    }

    fn number(&self) -> Option<f64> {
        match *self {
            Raw::Float(v) => Some(v),
            Raw::Integer(v) => Some(v as f64),
            _ => None,
        }
    }
}

impl<'de> Deserialize<'de> for Raw {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Raw, D::Error> {
        d.deserialize_any(RawVisitor)
    }
}

struct RawVisitor;

impl<'de> Visitor<'de> for RawVisitor {
    type Value = Raw;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a TOML value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<Raw, E> {
        Ok(Raw::Other("a boolean"))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Raw, E> {
        Ok(Raw::Integer(v.into()))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Raw, E> {
        Ok(Raw::Integer(v.into()))
    }

    fn visit_f64<E>(self, v: f64) -> Result<Raw, E> {
        Ok(Raw::Float(v))
    }

    fn visit_str<E>(self, v: &str) -> Result<Raw, E> {
        Ok(Raw::Str(v.to_string()))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Raw, A::Error> {
        let mut items = Vec::new();
        let mut count = 0usize;
        while count < MAX_ITEMS {
            match seq.next_element::<Spanned<Raw>>()? {
                Some(item) => items.push(item),
                None => return Ok(Raw::List(items, count)),
            }
            count += 1;
        }
        while seq.next_element::<IgnoredAny>()?.is_some() {
            count += 1;
        }
        Ok(Raw::List(items, count))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Raw, A::Error> {
        let mut entries = Vec::new();
        let mut count = 0usize;
        while let Some(key) = map.next_key::<Spanned<String>>()? {
            if count < MAX_ITEMS {
                entries.push((key, map.next_value::<Spanned<Raw>>()?));
            } else {
                map.next_value::<IgnoredAny>()?;
            }
            count += 1;
        }
        Ok(Raw::Table(entries, count))
    }
}

fn error(message: impl Into<String>, span: Range<usize>, help: &str) -> WorldError {
    WorldError::new(message, Some(span), help)
}

/// Where a list of numbers is: the list, and each number.
type Located = (Range<usize>, Vec<Range<usize>>);

/// The spans a range error can point at.
#[derive(Default)]
struct Spans {
    x: Option<Located>,
    y: Option<Located>,
    step: Range<usize>,
    headings: Range<usize>,
    slip: Option<Range<usize>>,
    noise: Option<Range<usize>>,
    obstacles: Option<Range<usize>>,
    /// Per obstacle: its list of numbers and each number.
    obstacle: Vec<Located>,
    start: Option<Located>,
    /// The `kind` value: what a missing key points at.
    kind: Range<usize>,
}

impl Spans {
    fn of(&self, field: Field) -> Range<usize> {
        let pick = |whole: &Option<Located>, i: Option<usize>| {
            whole.as_ref().map(|(all, each)| i.and_then(|i| each.get(i)).unwrap_or(all).clone())
        };
        let span = match field {
            Field::X(i) => pick(&self.x, i),
            Field::Y(i) => pick(&self.y, i),
            Field::Step => Some(self.step.clone()),
            Field::Headings => Some(self.headings.clone()),
            Field::Slip => self.slip.clone(),
            Field::Noise => self.noise.clone(),
            Field::Obstacles => self.obstacles.clone(),
            Field::Obstacle(k, i) => self
                .obstacle
                .get(k)
                .map(|(all, each)| i.and_then(|i| each.get(i)).unwrap_or(all).clone()),
            Field::Start(i) => pick(&self.start, i),
        };
        span.unwrap_or_else(|| self.kind.clone())
    }
}

/// `n` numbers, as `value` must hold them: `desc` says how ("two numbers [lo, hi]").
fn numbers(
    key: &str,
    value: &Spanned<Raw>,
    n: usize,
    desc: &str,
    help: &str,
) -> Result<(Vec<f64>, Located), WorldError> {
    let Raw::List(items, count) = value.get_ref() else {
        let message = format!("{key} must be {desc}, not {}", value.get_ref().what());
        return Err(error(message, value.span(), help));
    };
    if *count != n {
        return Err(error(format!("{key} must be {desc}, not {count}"), value.span(), help));
    }
    let mut out = Vec::with_capacity(n);
    for item in items {
        let Some(v) = item.get_ref().number() else {
            let message =
                format!("{key} must be {desc}, not a list holding {}", item.get_ref().what());
            return Err(error(message, item.span(), help));
        };
        out.push(v);
    }
    Ok((out, (value.span(), items.iter().map(Spanned::span).collect())))
}

/// A key the file must have; a missing one is reported at `kind = "plane"`.
fn required<'a>(
    value: &'a Option<Spanned<Raw>>,
    key: &str,
    help: &str,
    kind: &Range<usize>,
) -> Result<&'a Spanned<Raw>, WorldError> {
    value
        .as_ref()
        .ok_or_else(|| error(format!("the plane world has no `{key}`"), kind.clone(), help))
}

/// One number.
fn number(key: &str, value: &Spanned<Raw>, help: &str) -> Result<f64, WorldError> {
    value.get_ref().number().ok_or_else(|| {
        error(format!("{key} must be a number, not {}", value.get_ref().what()), value.span(), help)
    })
}

/// Reads a plane world from the file's table (`kind = "plane"`).
pub(super) fn parse(
    table: Spanned<DeTable<'_>>,
    default_name: &str,
) -> Result<PlaneWorld, WorldError> {
    refuse_dates(table.get_ref())?;
    let file = PlaneFile::deserialize(toml::de::Deserializer::from(table)).map_err(|e| {
        let message = e.message().trim_end_matches(['\n', '.']).replace('\n', "; ");
        WorldError::new(message, e.span(), KEYS_HELP)
    })?;
    let kind = file.kind.as_ref().map_or(0..0, Spanned::span);
    let name = match &file.name {
        None => None,
        Some(n) => match n.get_ref() {
            Raw::Str(s) => Some((s.as_str(), n.span())),
            other => {
                let message = format!("name must be a string, not {}", other.what());
                return Err(error(message, n.span(), super::NAME_HELP));
            }
        },
    };
    let name = world_name(name, default_name)?;
    let mut spans = Spans { kind: kind.clone(), ..Spans::default() };

    let extent = |key: &str, example: &str| -> Result<_, WorldError> {
        let help = format!("add the extent along {key}, such as `{key} = {example}`");
        let value = required(if key == "x" { &file.x } else { &file.y }, key, &help, &kind)?;
        let (v, at) = numbers(key, value, 2, "two numbers [lo, hi]", EXTENT_HELP)?;
        Ok(([v[0], v[1]], at))
    };
    let (x, x_at) = extent("x", "[0.0, 20.0]")?;
    let (y, y_at) = extent("y", "[0.0, 10.0]")?;
    spans.x = Some(x_at);
    spans.y = Some(y_at);

    let step =
        required(&file.step, "step", "add how far one move goes, such as `step = 0.5`", &kind)?;
    spans.step = step.span();
    let step = number("step", step, STEP_HELP)?;

    let headings = required(
        &file.headings,
        "headings",
        "add the number of headings, such as `headings = 4` (E N W S)",
        &kind,
    )?;
    spans.headings = headings.span();
    let headings = match *headings.get_ref() {
        Raw::Integer(n) => usize::try_from(n).ok().filter(|n| *n <= 64).ok_or(n as f64),
        Raw::Float(v) if v.fract() == 0.0 && (0.0..=64.0).contains(&v) => Ok(v as usize),
        Raw::Float(v) => Err(v),
        ref other => {
            let message = format!("headings must be a whole number, not {}", other.what());
            return Err(error(message, headings.span(), HEADINGS_HELP));
        }
    }
    .map_err(|v| {
        let message = format!("headings = {} is not a whole number from 3 to 64", num(v));
        error(message, spans.headings.clone(), HEADINGS_HELP)
    })?;

    let optional = |value: &Option<Spanned<Raw>>, key: &str, help: &str| match value {
        None => Ok((0.0, None)),
        Some(v) => number(key, v, help).map(|n| (n, Some(v.span()))),
    };
    let (slip, slip_at) = optional(&file.slip, "slip", SLIP_HELP)?;
    let (noise, noise_at) = optional(&file.noise, "noise", NOISE_HELP)?;
    spans.slip = slip_at;
    spans.noise = noise_at;

    let mut obstacles = Vec::new();
    if let Some(list) = &file.obstacles {
        spans.obstacles = Some(list.span());
        let Raw::List(items, count) = list.get_ref() else {
            let message = format!(
                "obstacles must be a list of circles and rectangles, not {}",
                list.get_ref().what()
            );
            return Err(error(message, list.span(), OBSTACLES_HELP));
        };
        if *count > MAX_OBSTACLES {
            let message = format!(
                "the world has {count} obstacles, more than the {MAX_OBSTACLES} a world may have"
            );
            return Err(error(message, list.span(), "merge obstacles, or leave some out"));
        }
        obstacles.reserve(*count);
        for item in items {
            let (obstacle, at) = obstacle(item)?;
            obstacles.push(obstacle);
            spans.obstacle.push(at);
        }
    }

    let start = match &file.start {
        None => None,
        Some(value) => {
            let (v, at) = numbers("start", value, 4, "four numbers [x0, y0, x1, y1]", START_HELP)?;
            spans.start = Some(at);
            Some([v[0], v[1], v[2], v[3]])
        }
    };

    let config = PlaneConfig { x, y, step, headings, slip, noise, obstacles, start };
    PlaneWorld::build(&name, config)
        .map_err(|ConfigError { field, message, help }| error(message, spans.of(field), help))
}

/// Refuses the first date in the table: no plane world value is one, and toml hands dates
/// to a spanned value in a form that cannot be worded.
fn refuse_dates(table: &DeTable<'_>) -> Result<(), WorldError> {
    // An explicit stack: nesting depth is the file's, not bounded by us.
    let mut stack: Vec<&Spanned<DeValue<'_>>> = table.values().collect();
    while let Some(value) = stack.pop() {
        match value.get_ref() {
            DeValue::Datetime(_) => {
                return Err(error(
                    "a date is not a value of a plane world",
                    value.span(),
                    "write numbers, lists of numbers and obstacle tables; see `kind = \"plane\"` in the docs",
                ));
            }
            DeValue::Array(items) => stack.extend(items.iter()),
            DeValue::Table(t) => stack.extend(t.values()),
            _ => {}
        }
    }
    Ok(())
}

/// One obstacle, `{ circle = [cx, cy, r] }` or `{ rect = [x0, y0, x1, y1] }`, with the
/// spans of its list and numbers.
fn obstacle(item: &Spanned<Raw>) -> Result<(Obstacle, Located), WorldError> {
    let Raw::Table(entries, count) = item.get_ref() else {
        let message = format!(
            "an obstacle must be a table such as `{{ circle = [cx, cy, r] }}`, not {}",
            item.get_ref().what()
        );
        return Err(error(message, item.span(), OBSTACLE_HELP));
    };
    let (key, value) = match (entries.first(), *count) {
        (Some(entry), 1) => entry,
        (_, 0) => {
            return Err(error(
                "an obstacle must be a circle or a rect, not an empty table",
                item.span(),
                OBSTACLE_HELP,
            ));
        }
        _ => {
            let message = format!("an obstacle has one key, `circle` or `rect`, not {count}");
            return Err(error(message, item.span(), OBSTACLE_HELP));
        }
    };
    match key.get_ref().as_str() {
        "circle" => {
            let (v, at) = numbers("a circle", value, 3, "three numbers [cx, cy, r]", CIRCLE_HELP)?;
            Ok((Obstacle::Circle { cx: v[0], cy: v[1], r: v[2] }, at))
        }
        "rect" => {
            let (v, at) = numbers("a rect", value, 4, "four numbers [x0, y0, x1, y1]", RECT_HELP)?;
            Ok((Obstacle::Rect { x0: v[0], y0: v[1], x1: v[2], y1: v[3] }, at))
        }
        other => {
            let message = format!(
                "unknown obstacle `{}`: an obstacle is a `circle` or a `rect`",
                crate::words::visible(other)
            );
            Err(error(message, key.span(), OBSTACLE_HELP))
        }
    }
}
