//! Syntax error wording: what pest expected, in the language's words.

use super::*;

/// Parses `text` again with pest's error details on, which name the literal tokens that
/// were expected (`;`, `&&`, ...). Details are switched on for the rest of the process
/// rather than toggled, so that parallel parses always see the same setting once an
/// error has been seen; they cost time only on the slow path of reporting.
pub(super) fn reparse_with_detail(rule: Rule, text: &str) -> Option<pest::error::Error<Rule>> {
    pest::set_error_detail(true);
    DETAILS_ON.store(true, std::sync::atomic::Ordering::Release);
    HstlParser::parse(rule, text).err()
}

/// Whether pest collects error details: set right after pest's own switch, so a parse
/// that starts after reading `true` here has them.
pub(super) static DETAILS_ON: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Parses `text` as `rule`; an error comes with pest's details (parsed a second time with
/// them if they were off).
pub(super) fn parse_detailed(
    rule: Rule,
    text: &str,
) -> Result<Pairs<'_, Rule>, pest::error::Error<Rule>> {
    let detailed = DETAILS_ON.load(std::sync::atomic::Ordering::Acquire);
    HstlParser::parse(rule, text)
        .map_err(|e| if detailed { e } else { reparse_with_detail(rule, text).unwrap_or(e) })
}

/// Groups the literal tokens pest expected into a few readable words.
pub(super) fn describe_tokens(tokens: Vec<String>) -> Vec<String> {
    const NOISE: [&str; 8] = ["/*", "//", "\u{feff}", ".", "e", "E", "BUILTIN_RULE", "+"];
    let mut set: std::collections::BTreeSet<String> = tokens
        .into_iter()
        .filter(|t| !(t.trim().is_empty() || t.len() == 4 && t.get(1..3) == Some("..")))
        .collect();
    // `+` alone is the exponent sign of a number; as an operator it comes with `*` and `/`.
    if set.contains("*") {
        set.insert("plus".into());
    }
    for n in NOISE {
        set.remove(n);
    }
    let mut out = Vec::new();
    let take = |set: &mut std::collections::BTreeSet<String>, group: &[&str]| -> bool {
        let mut any = false;
        for g in group {
            any |= set.remove(*g);
        }
        any
    };
    if take(
        &mut set,
        &["!", "always", "eventually", "once", "historically", "prev", "next", "true", "false"],
    ) {
        take(&mut set, &["(", "-", "abs", "sqrt", "_"]);
        out.push("a formula".to_string());
    } else if take(&mut set, &["abs", "sqrt"]) {
        take(&mut set, &["(", "-", "_"]);
        out.push("an expression".to_string());
    }
    if take(&mut set, &["_"]) {
        out.push("a name".to_string());
    }
    let cmp = take(&mut set, &["<", "<=", ">", ">=", "==", "!="]);
    let arith = take(&mut set, &["plus", "-", "*", "/"]);
    let logic = ["&&", "||", "->", "until", "since"].iter().any(|t| set.contains(*t));
    if cmp as u8 + arith as u8 + logic as u8 >= 2 {
        take(&mut set, &["&&", "||", "->", "until", "since"]);
        out.push("an operator".to_string());
    } else if cmp {
        out.push("a comparison operator".to_string());
    } else if arith {
        out.push("an arithmetic operator".to_string());
    }
    out.extend(set.into_iter().map(|t| format!("`{t}`")));
    out
}

/// Readable words for the rules pest reports as expected; `None` hides a rule.
pub(super) fn rule_words(r: Rule) -> Option<&'static str> {
    Some(match r {
        Rule::ident => "a name",
        Rule::number | Rule::neg_number => "a number",
        Rule::doc => "a doc comment",
        Rule::formula => "a formula",
        Rule::paren_f => "a formula",
        Rule::comparison | Rule::expr => "an expression",
        Rule::cmp_op => "a comparison operator",
        Rule::add_op | Rule::mul_op => "an arithmetic operator",
        Rule::implies_op => "`->`",
        Rule::until_op => "`until`",
        Rule::since_op => "`since`",
        Rule::not_op => "`!`",
        Rule::or_op => "`||`",
        Rule::and_op => "`&&`",
        Rule::neg_op => "`-`",
        Rule::always_op => "`always`",
        Rule::eventually_op => "`eventually`",
        Rule::once_op => "`once`",
        Rule::historically_op => "`historically`",
        Rule::prev_op => "`prev`",
        Rule::next_op => "`next`",
        Rule::interval => "an interval such as `[0..40]`",
        Rule::incl_op | Rule::excl_op | Rule::range_op => "`..` or `..=`",
        Rule::var => "a state variable",
        Rule::var_type => "`int`, `float` or `time`",
        Rule::range_lit => "a range such as `0..=14`",
        Rule::field => "an option field (`reach`, `init` or `terminate`)",
        Rule::field_value => "a formula or `argmax`",
        Rule::option_body => "`;` or `{`",
        Rule::options_list => "`{`",
        Rule::options_gen | Rule::gen_kind => "`sequences` or `permutations`",
        Rule::seq => "an option name or `[A, B, ...]`",
        Rule::param => "a learning parameter",
        Rule::param_name => "a parameter name",
        Rule::param_value => "a parameter value",
        Rule::param_group => "`{`",
        Rule::state_item
        | Rule::let_item
        | Rule::task_item
        | Rule::option_item
        | Rule::options_item
        | Rule::learn_item
        | Rule::world_item => {
            "an item (`state`, `let`, `task`, `option`, `options`, `learn` or `world`)"
        }
        Rule::string => "a string such as `\"four-rooms\"`",
        Rule::k_world => "`world`",
        Rule::func => "`abs` or `sqrt`",
        Rule::call => "a function call",
        Rule::k_spec => "`spec`",
        Rule::k_state => "`state`",
        Rule::k_int => "`int`",
        Rule::k_float => "`float`",
        Rule::k_time => "`time`",
        Rule::k_in => "`in`",
        Rule::k_let => "`let`",
        Rule::k_task => "`task`",
        Rule::k_option => "`option`",
        Rule::k_options => "`options`",
        Rule::k_sequences => "`sequences`",
        Rule::k_permutations => "`permutations`",
        Rule::k_learn => "`learn`",
        Rule::k_always => "`always`",
        Rule::k_eventually => "`eventually`",
        Rule::k_until => "`until`",
        Rule::k_once => "`once`",
        Rule::k_historically => "`historically`",
        Rule::k_since => "`since`",
        Rule::k_prev => "`prev`",
        Rule::k_next => "`next`",
        Rule::k_true => "`true`",
        Rule::k_false => "`false`",
        Rule::k_abs => "`abs`",
        Rule::k_sqrt => "`sqrt`",
        Rule::k_argmax => "`argmax`",
        Rule::EOI => "the end of the item",
        _ => return None,
    })
}
