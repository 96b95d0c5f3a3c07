fn main() {
    let path = std::env::args().nth(1).unwrap();
    let src = std::fs::read_to_string(&path).unwrap();
    let p = hstl_lang::parse(&src);
    if std::env::args().nth(2).is_some() {
        println!("{:#?}", p.file);
    }
    for d in &p.diagnostics {
        println!(
            "{:?} {} {:?} {} {:?}",
            d.code,
            d.message,
            d.range,
            &src[d.range.clone()],
            d.labels
        );
    }
}
