//! Every diagnostic code with its name, severity, summary and long explanation.
//! `hstlc explain CODE` prints [`CodeInfo::explanation`]. Codes are stable: new ones are
//! added at the end.

use crate::severity::Severity;

/// One diagnostic code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CodeInfo {
    /// The code, such as `HSTL003`.
    pub code: &'static str,
    /// A short kebab-case name, such as `duplicate-name`.
    pub name: &'static str,
    /// Error or warning.
    pub severity: Severity,
    /// One line.
    pub summary: &'static str,
    /// What triggers it, an example that does, and the fix.
    pub explanation: &'static str,
}

/// Looks a code up (case-insensitive).
pub fn lookup(code: &str) -> Option<&'static CodeInfo> {
    // Every diagnostic looks its code up: the exact spelling by binary search (the table is
    // sorted), any other case by a scan.
    match CODES.binary_search_by(|c| c.code.cmp(code)) {
        Ok(i) => Some(&CODES[i]),
        Err(_) => CODES.iter().find(|c| c.code.eq_ignore_ascii_case(code)),
    }
}

use Severity::{Error as E, Warning as W};

/// The table of every code, in numeric order.
pub static CODES: &[CodeInfo] = &[
    CodeInfo {
        code: "HSTL001",
        name: "syntax-error",
        severity: E,
        summary: "the text does not follow the grammar",
        explanation: "The parser expected something else at this place; the message says what it \
expected and what it found. Each item (`let`, `task`, `option`, ...) is parsed on its own, so \
an error in one item does not hide errors in the others: the broken item is skipped.\n\n\
Example:\n    let A = x > 3     // missing `;`\n    let B = y < 2;\n\n\
Fix: write what the message asks for (here `;`). Brackets nested more than 64 levels deep \
and formulas more than 256 levels tall are also reported under this code: split them into \
several `let`s.",
    },
    CodeInfo {
        code: "HSTL002",
        name: "unknown-name",
        severity: E,
        summary: "a name that is not declared",
        explanation: "A name in a formula must be a `let`; a name in an arithmetic expression \
must be a state variable. This one is neither.\n\n\
Example:\n    state { x: int in 0..=9 }\n    let A = z > 3;    // `z` is not declared\n\n\
Fix: declare the variable in `state { ... }` or the formula with `let`, or correct the \
spelling (the help suggests a close name when there is one).",
    },
    CodeInfo {
        code: "HSTL003",
        name: "duplicate-name",
        severity: E,
        summary: "a name (or a once-only item) is declared twice",
        explanation: "State variables and `let`s share one namespace, options have their own, and \
spec names must be unique in a file. A spec has at most one `state`, `task`, `options` and \
`learn` item. The label points at the first declaration.\n\n\
Example:\n    let A = x > 3;\n    let A = x < 9;\n\n\
Fix: rename one of them, or merge the two items.",
    },
    CodeInfo {
        code: "HSTL004",
        name: "let-cycle",
        severity: E,
        summary: "a `let` refers to itself, directly or through other lets",
        explanation: "A `let` names a formula; a definition that uses itself has no meaning. The \
message names the cycle.\n\n\
Example:\n    let A = B && x > 1;\n    let B = A || y > 2;\n\n\
Fix: write one of the formulas without the reference.",
    },
    CodeInfo {
        code: "HSTL005",
        name: "empty-interval",
        severity: E,
        summary: "an empty or inverted interval or `int` range",
        explanation: "`[a..b]` covers the steps a to b - 1 and is empty when b <= a; `[a..=b]` \
is empty when b < a. The same holds for `int` ranges such as `in 5..2`.\n\n\
Example:\n    task eventually[5..2] A;\n    task eventually[3..3] A;\n\n\
Fix: swap the bounds, or use `..=` to include the upper one (`[3..=3]` is the single step 3).",
    },
    CodeInfo {
        code: "HSTL006",
        name: "non-integer-bound",
        severity: E,
        summary: "an interval bound or `int` range bound that is not a whole number",
        explanation: "Time is discrete: interval bounds count steps. `int` ranges hold \
integers. Bounds must be written as plain digits.\n\n\
Example:\n    task eventually[0..2.5] A;\n    state { x: int in 0..=1e3 }\n\n\
Fix: write an integer, such as `[0..3]` or `0..=1000`. Decimal bounds such as `[0..=2.5]` \
belong to dense-time specs, which monitor time-stamped traces: declare the time column in \
`state` (`t: time`). In a dense-time spec this code reports a bound with more digits than \
fit (at most 18 in all, counted at the spec's longest fraction).",
    },
    CodeInfo {
        code: "HSTL007",
        name: "equality",
        severity: E,
        summary: "`==` or `!=` in a comparison",
        explanation: "Robustness measures how far a comparison is from flipping; equality has no \
useful robustness (it holds on a set of measure zero).\n\n\
Example:\n    let Home = x == 3;\n\n\
Fix: use a band, such as `abs(x - 3) < 0.5`, or `2 < x < 4` on an integer grid.",
    },
    CodeInfo {
        code: "HSTL008",
        name: "kind-mismatch",
        severity: E,
        summary: "a formula where a number is expected, or the reverse",
        explanation: "Comparisons relate numbers (state variables, constants, arithmetic); \
`&&`, `||`, `!` and the temporal operators combine formulas (`let`s, comparisons). A `let` \
inside arithmetic, a state variable used as a formula, or `argmax` outside `terminate` is \
this error.\n\n\
Example:\n    let A = x > 3;\n    let B = A < 3;    // `A` is a formula\n\n\
Fix: compare the variables themselves, or combine formulas with `&&`, `||`.",
    },
    CodeInfo {
        code: "HSTL009",
        name: "temporal-in-option",
        severity: E,
        summary: "a temporal operator in `reach`, `init` or `terminate`",
        explanation: "An option's reach, initiation and termination conditions are evaluated on \
one state, so they must be state formulas: no temporal operator (`always`, `eventually`, \
`until`, `once`, `historically`, `since`, `prev`, `next`), also not through a `let`.\n\n\
Example:\n    let A = eventually[0..5] x > 3;\n    option A;\n\n\
Fix: reach a state formula, such as `let A = x > 3;`.",
    },
    CodeInfo {
        code: "HSTL010",
        name: "option-without-let",
        severity: E,
        summary: "an option that names no `let`",
        explanation: "`option A;` reaches the `let` named `A`; the long form without `reach` does \
too. There is no such `let`.\n\n\
Example:\n    let A = x > 3;\n    option Goal;\n\n\
Fix: declare `let Goal = ...;`, or give the option a `reach` field: \
`option Goal { reach: A }`.",
    },
    CodeInfo {
        code: "HSTL011",
        name: "unknown-option",
        severity: E,
        summary: "a sequence names an option that is not declared",
        explanation: "`options` lists and `sequences(...)`/`permutations(...)` combine declared \
primitive options only.\n\n\
Example:\n    option A;\n    options { A, [A, D] }\n\n\
Fix: declare `option D;` or remove it from the sequence.",
    },
    CodeInfo {
        code: "HSTL012",
        name: "repeated-option",
        severity: E,
        summary: "a sequence repeats an option",
        explanation: "A combined option runs each leg once; a repeated leg, or a name listed twice \
in `sequences(...)`/`permutations(...)`, is rejected.\n\n\
Example:\n    options { [A, B, A] }\n\n\
Fix: remove the repetition.",
    },
    CodeInfo {
        code: "HSTL013",
        name: "option-name-collision",
        severity: E,
        summary: "two options of the set get the same generated name",
        explanation: "Every option of the set is named by concatenating its legs' names (`A`, \
`AB`, `ABC`). Two entries with the same name cannot be told apart, in `policy.json` nor in \
generated code.\n\n\
Example:\n    option A; option B; option AB;\n    options { AB, [A, B] }\n\n\
Fix: rename a primitive option (or the `let` it reaches) or drop one entry.",
    },
    CodeInfo {
        code: "HSTL014",
        name: "infinite-domain",
        severity: E,
        summary: "a state variable without bounds while options are declared",
        explanation: "Options are learned over the whole state space: with tables over every \
state of an `int` domain, or with tilings over the box of a `float` one (`learner: tiles`). \
Either needs bounds, so every state variable has a range when the spec declares an option.\n\n\
Example:\n    state { x: float, y: int }\n    option A;\n\n\
Fix: bound it, `x: float in 0..=14` or `y: int in 0..=14` (a world's extent or size), or \
remove the options (a spec without options is still a monitor).",
    },
    CodeInfo {
        code: "HSTL015",
        name: "missing-task",
        severity: E,
        summary: "a spec without a `task`",
        explanation: "Every spec needs the task its options are rewarded for.\n\n\
Example:\n    spec S { state { x: int in 0..=3 } let A = x > 1; }\n\n\
Fix: add `task always[0..] eventually[0..10] A;` or similar.",
    },
    CodeInfo {
        code: "HSTL016",
        name: "parameter-out-of-range",
        severity: E,
        summary: "a learning parameter value out of range or of the wrong kind",
        explanation: "gamma and alpha lie in (0, 1]; 0 <= min_epsilon <= epsilon <= 1; decay >= \
0; episodes, choices and max_steps are whole numbers > 0; memory is a whole number >= 0; \
`intra` is `paper` or `remaining`; `reward` is `segment` or `window`; `flat` and `options` are \
groups `{ gamma: ..., ... }`.\n\n\
Example:\n    learn { episodes: 0, flat: { gamma: 1.5 } }\n\n\
Fix: use a value in the stated range.",
    },
    CodeInfo {
        code: "HSTL017",
        name: "task-not-persistent",
        severity: E,
        summary: "`memory` or `reward: window` with a task not of the form they need",
        explanation: "Both need a task `always[0..] (eventually[0..N1] R1 && ... && \
eventually[0..Nk] Rk)` where each Rj is a state formula: the memory tracks the steps since \
each Rj last held.\n\n\
Example:\n    task eventually[0..40] A;\n    learn { memory: 8 }\n\n\
Fix: write the task in that form, or remove `memory` and `reward: window`.",
    },
    CodeInfo {
        code: "HSTL018",
        name: "no-option-can-start",
        severity: E,
        summary: "a state of the domain where no option of the set can start",
        explanation: "The options policy must choose an option in every state it can reach. In \
this state every option's `init` (of its first leg) is false. The message shows one such \
state and how many there are.\n\n\
Example:\n    option A { reach: A, init: x < 5 }\n    options { A }\n\n\
Fix: widen the `init` conditions or add an option that can start there.",
    },
    CodeInfo {
        code: "HSTL019",
        name: "unknown-parameter",
        severity: E,
        summary: "an unknown or repeated parameter or option field name",
        explanation: "`learn` knows episodes, choices, max_steps, memory, intra, reward, flat and \
options; `flat`/`options` groups know gamma, alpha, epsilon, min_epsilon and decay; an option \
knows reach, init and terminate. Each may be given once.\n\n\
Example:\n    learn { episode: 100 }\n\n\
Fix: correct the spelling (the help suggests the closest name) or remove the repetition.",
    },
    CodeInfo {
        code: "HSTL020",
        name: "sequence-gap",
        severity: E,
        summary: "an option of a sequence can terminate where the next cannot start",
        explanation: "A combined option `[A, B]` runs `A` to termination and then `B`; every state \
where `A` may terminate must lie in `B`'s initiation set. The message shows a state where `A` \
terminates and `B` cannot start.\n\n\
Example:\n    option A { reach: A, terminate: A }\n    option B { reach: B, init: !A }\n    \
options { [A, B] }\n\n\
Fix: widen `B`'s `init`, or narrow `A`'s `terminate`.",
    },
    CodeInfo {
        code: "HSTL021",
        name: "until-chain",
        severity: E,
        summary: "`a until b until c` without parentheses",
        explanation: "`until` is not associative, so a chain is ambiguous and rejected. The same \
holds for `since`, and for `until` and `since` together.\n\n\
Example:\n    task a until b until c;\n    task a since b since c;\n\n\
Fix: add parentheses: `(a until b) until c` or `a until (b until c)`.",
    },
    CodeInfo {
        code: "HSTL022",
        name: "domain-too-large",
        severity: W,
        summary: "the declared domain is too large to enumerate",
        explanation: "The finite-domain checks (HSTL018, HSTL020, HSTL102, HSTL103, argmax \
termination sets) enumerate every state of the declared `int` domain, up to 1,000,000 states \
and 20,000,000 formula evaluations (states times the lets the regions use). Beyond that they \
are skipped, and tabular learning would be slow anyway.\n\n\
Example:\n    state { x: int in 0..=9999, y: int in 0..=9999 }\n\n\
Fix: shrink the ranges, or accept that those checks are skipped.",
    },
    CodeInfo {
        code: "HSTL023",
        name: "options-set-too-large",
        severity: E,
        summary: "the expanded options set has more than 10,000 options",
        explanation: "`sequences` of n options has 2^n - 1 members and `permutations` grows \
faster still; the default set is `sequences` of every declared option. Sets beyond 10,000 \
options are rejected.\n\n\
Example:\n    options permutations(A, B, C, D, E, F, G, H);\n\n\
Fix: list the sequences you need with `options { ... }`.",
    },
    CodeInfo {
        code: "HSTL024",
        name: "too-many-diagnostics",
        severity: W,
        summary: "more diagnostics were found than are reported",
        explanation: "At most 200 diagnostics are reported per file; this one says how many more \
there were (it is an error when some of those were errors).\n\n\
Fix: fix the reported ones and check again.",
    },
    CodeInfo {
        code: "HSTL025",
        name: "argmax-needs-finite-domain",
        severity: E,
        summary: "`terminate: argmax` over a `float` state",
        explanation: "An option without `terminate` (or with `terminate: argmax`, the paper's \
rule) stops in the states where its region's robustness is largest. Those states are found by \
enumerating the domain, which a `float` variable does not allow; on a continuous state the \
most robust point is usually a single point the robot never hits exactly.\n\n\
Example:\n    state { x: float in 0..=14, y: float in 0..=14 }\n    let A = x > 12 && y > 12;\n    option A;\n\n\
Fix: stop on entering the region, `option A { terminate: A }`, or write `learn { preset: \
auto }`, which gives every option that form.",
    },
    CodeInfo {
        code: "HSTL030",
        name: "state-does-not-fit-world",
        severity: E,
        summary: "the state variables do not match the grid world",
        explanation: "A spec with options is trained in a grid world (`hstlc train --world`, \
`paper` by default), whose state is the robot's cell: `x` from 0 (left) to W-1 and `y` from \
0 (bottom) to H-1. The spec must declare exactly these two variables, as `int`s with exactly \
these ranges, so that every cell of the map is a state of the spec and back. `hstlc check \
--world FILE` checks against that world; without `--world` against `paper` (15 x 15).\n\n\
Example (for the 13 x 13 `four-rooms`):\n    state { x: int in 0..=14, y: int in 0..=14 }\n\n\
Fix: `state { x: int in 0..=12, y: int in 0..=12 }` (the help gives the ranges).",
    },
    CodeInfo {
        code: "HSTL031",
        name: "option-region-outside-world",
        severity: E,
        summary: "an option reaches a region with no free cell of the world",
        explanation: "The region an option reaches (its `reach`, or the `let` its name names) \
holds in no free cell of the map: every cell where it holds is a wall, or lies outside the \
map. The option could never succeed, so training it is pointless.\n\n\
Example (the wall row y = 6 of a map):\n    let Door = y == 6 && x < 2;   // every such cell is `#`\n    option Door;\n\n\
Fix: move the region onto free cells (`.` or `S`), or change the map.",
    },
    CodeInfo {
        code: "HSTL032",
        name: "option-never-stops",
        severity: E,
        summary: "an option's termination set holds in no state",
        explanation: "An option stops at the first state where its `terminate` formula holds \
(robustness > 0). No state of the domain, or with a world no free cell of its map, satisfies \
this one, so every leg runs until it is cut off after `max_steps` steps.\n\n\
Example:\n    option A { terminate: x > 20 }   // x runs over 0..=14\n\n\
Fix: widen `terminate`, or leave it out: the option then stops where its region is most robust.",
    },
    CodeInfo {
        code: "HSTL033",
        name: "memory-too-large",
        severity: E,
        summary: "memory or the window reward would need more than the stated limits",
        explanation: "Memory and `reward: window` keep a table entry per step of each window: \
windows of at most 1,000,000 steps (what the memory's values cost is HSTL084's). \
`plan: model` plans over the exact counters of every region and each leg's durations from \
every state: at most 67,108,864 planned values and 2,147,483,648 operations per sweep, \
counted from the states, the regions' sizes and the windows.\n\n\
Example:\n    task always[0..] eventually[0..2000000] A;\n    learn { memory: 8 }\n\n\
Fix: shorter windows, smaller or fewer regions for `plan: model`.",
    },
    CodeInfo {
        code: "HSTL034",
        name: "world-unavailable",
        severity: E,
        summary: "the world a spec names cannot be found or read",
        explanation: "`world \"NAME_OR_PATH\";` names the world a spec is written for: a \
built-in world (`paper`, `four-rooms`) or a world file, whose path is relative to the spec \
file. This one is no built-in name, and the file it names is missing, unreadable or \
malformed (the message says which, with the world file's line and column). `hstlc check`, \
`train` and `study` and the editor check the spec against the world it names; `--world` \
overrides it.\n\n\
Example:\n    world \"maps/yrad.toml\";   // the file is maps/yard.toml\n\n\
Fix: correct the name or the path (relative to the spec file), or fix the world file.",
    },
    CodeInfo {
        code: "HSTL050",
        name: "constant-reach",
        severity: E,
        summary: "an option's `reach` that refers to no state variable",
        explanation: "Robustness measures how far the state is from flipping a formula. The \
`reach` formula of a primitive option that refers to no state variable (directly or through \
the lets it uses) has the same robustness in every state: `inf` for `true`, `-inf` for \
`false`, a constant for `3 > 2`. The option's reward is then the same everywhere, and there \
is nothing for it to learn (an infinite reward at that). A task that refers to no state \
variable is only a warning (HSTL104): it can be monitored.\n\n\
Example:\n    let A = true;\n    option A;\n\n\
Fix: reach a region of the state, such as `let A = x > 3;`.",
    },
    CodeInfo {
        code: "HSTL051",
        name: "name-too-long",
        severity: E,
        summary: "a name longer than 64 characters",
        explanation: "Spec, state variable, `let` and option names are at most 64 characters \
long. Names become file names (`hstlc train` writes `flat_NAME.svg` for each option, and \
file systems cap a file name at 255 bytes) and labels in tables and pictures.\n\n\
Example:\n    option ReachTheLoadingDockOnTheFarSideOfTheWarehouseWithoutTouchingShelves;\n\n\
Fix: shorten the name, and say the rest in a doc comment (`/// ...`).",
    },
    CodeInfo {
        code: "HSTL060",
        name: "undefined-expression",
        severity: E,
        summary: "an expression that is NaN on a state of the declared domain",
        explanation: "Robustness is a number for every state; NaN has no meaning, and a min or \
max would skip it and hide the state. `sqrt` of a negative number, `0 / 0`, `inf / inf`, \
`0 * inf` and `inf - inf` are NaN. When every state variable is a finite `int`, the checker \
evaluates each comparison on every state of the declared domain and reports the first state \
where an expression is NaN, at the innermost expression that is. On `float` variables the \
monitors refuse such a step of a trace instead, naming the step and the expression.\n\n\
Example:\n    state { x: int in 0..=9 }\n    let Far = sqrt(x - 3) > 1;   // x = 0: the square root of -3\n\n\
Fix: keep the expression defined on the whole domain (`sqrt(abs(x - 3))`, a divisor that is \
never 0), or narrow the `int` ranges to the states the system can be in.",
    },
    CodeInfo {
        code: "HSTL070",
        name: "option-avoids-its-goal",
        severity: E,
        summary: "an option's `avoid` region holds in every state where it stops",
        explanation: "`avoid: R` keeps a leg out of `R`: its flat reward also sees `rho(!R)`, \
entering `R` costs more than any path that stays out, and the leg stops there. A state is in \
`R` where the robustness of `R` is 0 or more (`always !R` fails there). Every state where this \
option stops (its `terminate` set, or where its region is most robust) lies in `R`, so the leg \
can only succeed by entering the region it must avoid.\n\n\
Example:\n    let Goal = x > 10;\n    let Hazard = x > 8;\n    option Goal { avoid: Hazard }\n\n\
Fix: narrow the `avoid` region, or move the option's region out of it.",
    },
    CodeInfo {
        code: "HSTL071",
        name: "counterfactual-needs-memory",
        severity: E,
        summary: "`counterfactual` without `memory` and `reward: window`",
        explanation: "`counterfactual: M` makes every option execution also update the options \
value of M other memory values it could have started with: the memory's counters are run \
again along the same states from each of them, and the run is scored by the window reward \
it would have earned. Without `memory` the options level sees no memory values to update, \
and without `reward: window` the reward does not depend on them.\n\n\
Example:\n    learn { counterfactual: 8 }\n\n\
Fix: add `memory: 8, reward: window` (the task must be persistent), or write \
`learn { preset: auto }`, which sets all three on a persistent task.",
    },
    CodeInfo {
        code: "HSTL072",
        name: "plan-needs-persistent-options",
        severity: E,
        summary: "`plan: model` on a spec whose options level cannot be planned",
        explanation: "`plan: model` computes the options values after training instead of \
Q-learning them: from the transitions seen in training it estimates how long each option's leg \
takes from each state and where in its region it arrives, and runs value iteration over the \
memory's counters, which the task determines exactly. That needs a persistent task \
`always[0..] (eventually[0..N1] R1 && ...)`, `memory` and `reward: window` (the counters and \
the reward it plans with), an options gamma below 1, and options of one leg each that stop on \
entering one of the task's regions, without `avoid`. On a reach task `eventually[0..T] G && \
always !R` (one to four goals, each by its deadline) it plans the legs instead: each leg that \
stops on entering a goal takes the actions most likely, under the model, to enter it in time \
without entering `R`.\n\n\
Example:\n    task always[0..] eventually[0..40] A;\n    options sequences(A, B);\n    \
learn { memory: 8, reward: window, plan: model }\n\n\
Fix: write `option A;` per region and `learn { preset: auto }`, which sets `plan: model` on \
a persistent task or a reach task, or remove `plan: model`.",
    },
    CodeInfo {
        code: "HSTL080",
        name: "time-variable-declaration",
        severity: E,
        summary: "a second time variable, or a time variable with a range",
        explanation: "A state variable of type `time` names the trace column that holds the \
time stamps, which makes the spec a dense-time spec (see \"Time stamps and dense time\" in LANGUAGE.md). A \
trace has one time column, so a spec has at most one time variable, and stamps are any \
strictly increasing numbers, so it takes no range.\n\n\
Example:\n    state { t: time, stamp: time, x: float }\n    state { t: time in 0..=10 }\n\n\
Fix: keep one time variable, declared `t: time`; a second clock is a `float` variable.",
    },
    CodeInfo {
        code: "HSTL081",
        name: "no-dense-meaning",
        severity: E,
        summary: "`prev`, `next` or a half-open interval in a dense-time spec",
        explanation: "In a dense-time spec (one with a `time` variable) robustness is a \
function of continuous time. `prev` and `next` step to the previous or next sample, which \
continuous time does not have. A half-open interval `[a..b]` gives values that hold at \
single instants (`eventually[0..1]` of a step up at 1 differs at one instant alone), which \
the `t,robustness` change points cannot show. rtamt's dense-time STL has neither.\n\n\
Example:\n    state { t: time, x: float }\n    task eventually[0..2] prev x > 1;\n\n\
Fix: write closed intervals, `[0..=2]`; for `prev f` or `next f`, say how far back or ahead \
with an interval, such as `once[0..=0.1] f` or `eventually[0..=0.1] f`.",
    },
    CodeInfo {
        code: "HSTL082",
        name: "time-variable-in-formula",
        severity: E,
        summary: "a formula reads the time variable",
        explanation: "The time variable holds the trace's time stamps: it says when every \
other variable takes its values, and is not a signal itself. Robustness is a function of \
time, and the intervals of the temporal operators say when something must hold, relative to \
now; a comparison such as `t > 5` would depend on where the log's clock started (a ROS 2 \
bag counts nanoseconds since 1970).\n\n\
Example:\n    state { t: time, x: float }\n    task eventually (t > 5 && x > 1);\n\n\
Fix: say when with an interval: `eventually[5..] x > 1` (x exceeds 1 at some time at least \
5 after the first stamp).",
    },
    CodeInfo {
        code: "HSTL083",
        name: "learning-in-dense-spec",
        severity: E,
        summary: "an `option`, `options`, `learn` or `world` item in a dense-time spec",
        explanation: "A spec with a time variable monitors time-stamped traces (`hstlc \
monitor`); the learner moves in discrete steps on a world, so options, the options set, \
learning parameters and a world have no meaning in it.\n\n\
Example:\n    state { t: time, x: float }\n    let Goal = x > 1;\n    \
task eventually[0..=2.5] Goal;\n    option Goal;\n\n\
Fix: remove those items from the dense spec (keep the learning in a discrete-time spec of \
its own), or remove the time variable to learn in steps.",
    },
    CodeInfo {
        code: "HSTL084",
        name: "over-memory-budget",
        severity: E,
        summary: "the runs of a spec would take more than the 2 GiB memory budget",
        explanation: "Everything `check` accepts trains, evaluates and loads within a stated \
memory budget of 2 GiB (`study` runs fewer seeds at once when a spec needs it). The budget \
counts what the tabular learner holds: the Q-tables (options x memory values x states, and \
actions x states per primitive option), `policy.json` as written (an options-policy entry \
per state and memory value, a flat-policy entry per state and primitive), the document as \
`eval` and `hstl.Policy.load` read it back, and the exact optimum's tables; the states are \
the spec's `int` domain, which bounds the world's cells. `memory: B` over k regions gives \
(B + 1)^k memory values per state; a task that is not persistent has a row per set of goals \
met (2^goals, at most 4 goals), and `plan: model` on a reach task plans over the steps to its \
latest deadline. A goal is also written out in full in `policy.json`, every `let` wherever it \
is used: at most 1 MiB a goal, which nested lets that each use the one before twice pass \
quickly. On a `float` state it counts the learned function's weights instead (primitives x \
actions x flat features, and options x memory values x options features; at most 33,554,432 \
weights), with `policy.json` as if every weight were non-zero.\n\n\
Example:\n    learn { memory: 30 }   // 225 cells x 31^3 memory values: 6.7 million entries\n\n\
Fix: fewer memory values (a smaller `memory: B`, or fewer regions), a smaller world, or \
fewer options (on a `float` state, fewer tiles or tilings); a goal with fewer nested lets.",
    },
    CodeInfo {
        code: "HSTL101",
        name: "unused-let",
        severity: W,
        summary: "a `let` that neither the task nor any option uses",
        explanation: "A `let` is used when the task or an option refers to it, directly or through \
other used lets (a short-form `option A;` uses `A`).\n\n\
Example:\n    let Old = x > 3;    // nothing refers to it\n\n\
Fix: remove it, or use it. Generated code still gets a monitor for it.",
    },
    CodeInfo {
        code: "HSTL102",
        name: "empty-region",
        severity: W,
        summary: "a region no state of the domain satisfies",
        explanation: "A region is a `let` that an option reaches, or the state formula Rj of a \
task conjunct `eventually[0..N] Rj` under `always[0..]`. When the state domain is finite, \
every state is tried: none satisfies this one (robustness > 0), so its option cannot succeed \
and the task cannot be kept.\n\n\
Example:\n    state { x: int in 0..=14 }\n    let A = x > 20;\n\n\
Fix: correct the bounds (on an integer grid `3 < x < 4` is empty).",
    },
    CodeInfo {
        code: "HSTL103",
        name: "full-region",
        severity: W,
        summary: "a region every state of the domain satisfies",
        explanation: "Every state of the finite domain satisfies this region (see HSTL102 for \
what a region is), so reaching it needs no learning.\n\n\
Example:\n    state { x: int in 0..=14 }\n    let A = x >= 0;\n\n\
Fix: tighten the formula.",
    },
    CodeInfo {
        code: "HSTL104",
        name: "constant-task",
        severity: W,
        summary: "a task that refers to no state variable",
        explanation: "A task that refers to no state variable (directly or through the lets it \
uses) has the same robustness at every step: `always[1..6] (1 >= 2)` is -1 on every trace, \
`true` is `inf`. It is valid STL, and `hstlc monitor` computes it as rtamt does, but it is \
probably not what was meant, and there is nothing to learn from it: `hstlc train` (and \
`hstl.train`) refuse such a task.\n\n\
Example:\n    task always[1..6] (1 >= 2);\n\n\
Fix: write the task over the state, such as `task always[0..] eventually[0..40] A;` with \
`let A = x > 3;`.",
    },
    CodeInfo {
        code: "HSTL131",
        name: "region-unreachable",
        severity: W,
        summary: "no start of the world can reach a region",
        explanation: "Walls cut the map into parts, and every cell of this region lies in a part \
that no start cell reaches: episodes start on the `S` cells (or on every free cell of a map \
without `S`), and the robot never crosses a wall. The task's windows that need the region can \
then never be kept.\n\n\
Example: a region inside a closed room of the map.\n\n\
Fix: open a doorway (`.`) in the wall, add a start cell on the region's side, or move the region.",
    },
    CodeInfo {
        code: "HSTL150",
        name: "inclusive-bound-on-int",
        severity: W,
        summary: "`<=` or `>=` between an `int` variable and a whole number",
        explanation: "The robustness of `x <= 3` is `3 - x`, the same as that of `x < 3`, and a \
formula holds where its robustness is above 0. On an `int` variable the bound itself is a \
cell, where the robustness is exactly 0: `x <= 3` does not hold at `x = 3`, and \
`2 <= y <= 3` holds in no cell at all, though it reads as the cells 2 and 3.\n\n\
Example:\n    state { y: int in 0..=14 }\n    let Door = 2 <= y <= 3;\n\n\
Fix: write strict comparisons one step outside the cells you mean: `1 < y < 4`.",
    },
    CodeInfo {
        code: "HSTL170",
        name: "safety-unseen-by-options",
        severity: W,
        summary: "a safety conjunct `always !R` of the task that no option's reward sees",
        explanation: "The options level is rewarded by the task's robustness, but each leg is \
learned from its own region alone (`rho(reach, s')` per step): a conjunct `always !R` of the \
task (bounded or not) shapes nothing below the options level, and the learned legs take the \
shortest way to their region, through `R` if it lies on the way. Give the options \
`avoid: R`: the leg's reward then also sees `rho(!R)`, entering `R` costs more than any path \
that stays out, and the leg stops there. `learn { preset: auto }` fills it in on every option.\n\n\
Example:\n    task eventually[0..=30] Goal && always !Pit;\n    option Goal;   // its leg may cross Pit\n\n\
Fix: `option Goal { avoid: Pit }`, or `learn { preset: auto }`.",
    },
    CodeInfo {
        code: "HSTL180",
        name: "large-memory-estimate",
        severity: W,
        summary: "the runs of a spec will take more than 512 MiB",
        explanation: "The memory model of HSTL084 puts `train` or `eval` of this spec above \
512 MiB, within the 2 GiB budget: it runs, and the note says how much it will take (and \
how large `policy.json` will be) before it does.\n\n\
Example:\n    learn { memory: 20 }   // 225 cells x 21^3 memory values: 2.1 million entries\n\n\
Fix: nothing is wrong; fewer memory values, a smaller world or fewer options make it \
smaller.",
    },
    CodeInfo {
        code: "HSTL190",
        name: "unbounded-past-in-long-runs",
        severity: W,
        summary: "a past window without an end, or over 256 steps, in a task trained with long runs",
        explanation: "The options level rewards each option run by the task's robustness over \
the run, and credits every suffix of the run as a run of its own (the paper's intra-option \
credit). A past window reads the steps before `t` down to the run's start, so a suffix is \
not the run's tail there. A short window (`once[0..=k]`) differs only in the first `k` \
steps of each suffix, and scoring a run costs `k` steps per step. A window without an end \
reads back to each suffix's own start: scoring every suffix would cost `max_steps^2 / 2` \
steps for one run, minutes at `max_steps: 100000`.\n\n\
So training holds the steps scored for a run's suffixes to 256 per step of the run. Past \
that, it scores the suffixes from every `s`-th step of the run, with the smallest `s` that \
fits, each exactly, and leaves the others out of the options level's updates (the paper's \
SMDP update uses the first alone). A window without an end on runs of `m` steps keeps about \
512 suffixes a run; a window of `k` steps about one in `k / 256`. The warning says how many \
at the spec's `max_steps`.\n\n\
Example:\n    task always[0..] (once[0..] alarm > 0 -> speed < 5);\n    learn { max_steps: 100000 }\n\n\
Fix: give the window an end of at most 256 steps (`once[0..=200]`), or keep `max_steps` at \
500 or less.",
    },
];
