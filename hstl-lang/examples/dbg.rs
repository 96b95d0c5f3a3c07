//! Scratch.
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let src = std::fs::read_to_string(&path).unwrap();
    let c = hstl_lang::check(&src);
    if std::env::args().nth(2).is_some() {
        println!("{:#?}", c.specs);
    }
    print!("{}", hstl_lang::render_plain(&path, &src, &c.diagnostics));
}
