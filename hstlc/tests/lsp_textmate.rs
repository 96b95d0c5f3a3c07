//! `editors/hstl.tmLanguage.json`: it parses as JSON, every regex compiles (the grammar
//! sticks to the syntax that Oniguruma and the `regex` crate share), every include
//! resolves, and the rules give each keyword of the language and each comment kind the
//! scope it should have.

use std::path::Path;

use regex::Regex;
use serde_json::Value;

fn grammar() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../editors/hstl.tmLanguage.json");
    let text = std::fs::read_to_string(&path).expect("read the grammar");
    serde_json::from_str(&text).expect("the grammar is JSON")
}

/// Every `(scope name, regex)` of rules with a `match`, and every other regex string.
fn walk(
    v: &Value,
    rules: &mut Vec<(String, String)>,
    others: &mut Vec<String>,
    includes: &mut Vec<String>,
) {
    match v {
        Value::Object(map) => {
            if let Some(Value::String(m)) = map.get("match") {
                let name = map.get("name").and_then(Value::as_str).unwrap_or("").to_string();
                rules.push((name, m.clone()));
            }
            for key in ["begin", "end"] {
                if let Some(Value::String(r)) = map.get(key) {
                    others.push(r.clone());
                }
            }
            if let Some(Value::String(i)) = map.get("include") {
                includes.push(i.clone());
            }
            map.values().for_each(|x| walk(x, rules, others, includes));
        }
        Value::Array(items) => items.iter().for_each(|x| walk(x, rules, others, includes)),
        _ => {}
    }
}

#[test]
fn the_grammar_parses_and_its_regexes_compile() {
    let g = grammar();
    assert_eq!(g["scopeName"], "source.hstl");
    assert!(g["fileTypes"].as_array().is_some_and(|a| a.iter().any(|t| t == "hstl")));
    let (mut rules, mut others, mut includes) = (Vec::new(), Vec::new(), Vec::new());
    walk(&g, &mut rules, &mut others, &mut includes);
    assert!(rules.len() > 15, "only {} rules", rules.len());
    for r in rules.iter().map(|r| &r.1).chain(&others) {
        Regex::new(r).unwrap_or_else(|e| panic!("{r}: {e}"));
    }
    let repo = g["repository"].as_object().expect("a repository");
    for i in includes {
        let key = i.strip_prefix('#').unwrap_or_else(|| panic!("include {i} is not local"));
        assert!(repo.contains_key(key), "include {i} names nothing");
    }
}

/// The scope of the first rule (in order) that matches all of `text`.
fn scope_of(rules: &[(String, Regex)], text: &str) -> Option<String> {
    rules
        .iter()
        .find(|(_, re)| re.find(text).is_some_and(|m| m.start() == 0 && m.end() == text.len()))
        .map(|(name, _)| name.clone())
}

#[test]
fn keywords_and_comments_get_their_scopes() {
    let g = grammar();
    let (mut raw, mut others, mut includes) = (Vec::new(), Vec::new(), Vec::new());
    for key in ["comments", "keywords", "operators", "numbers"] {
        walk(&g["repository"][key], &mut raw, &mut others, &mut includes);
    }
    let rules: Vec<(String, Regex)> =
        raw.into_iter().map(|(n, r)| (n, Regex::new(&r).expect("compiles"))).collect();
    // Every keyword of the grammar.
    for k in hstl::lang::KEYWORDS {
        let scope = scope_of(&rules, k).unwrap_or_else(|| panic!("`{k}` is not highlighted"));
        assert!(
            ["keyword.", "storage.", "constant.", "support."].iter().any(|p| scope.starts_with(p)),
            "`{k}` gets {scope}"
        );
    }
    assert_eq!(scope_of(&rules, "/// Doc.").as_deref(), Some("comment.line.documentation.hstl"));
    assert_eq!(scope_of(&rules, "// plain").as_deref(), Some("comment.line.double-slash.hstl"));
    assert_eq!(scope_of(&rules, "//// plain").as_deref(), Some("comment.line.double-slash.hstl"));
    assert_eq!(scope_of(&rules, "1e-6").as_deref(), Some("constant.numeric.hstl"));
    for op in ["->", "&&", "||", "!"] {
        assert_eq!(scope_of(&rules, op).as_deref(), Some("keyword.operator.logical.hstl"), "{op}");
    }
    for op in ["<", "<=", ">", ">=", "!="] {
        assert_eq!(
            scope_of(&rules, op).as_deref(),
            Some("keyword.operator.comparison.hstl"),
            "{op}"
        );
    }
}
