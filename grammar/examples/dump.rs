fn main() {
    let p = std::env::args().nth(1).unwrap();
    let s = std::fs::read_to_string(p).unwrap();
    let (f, d) = lensc_grammar::parse(&s, lensc_grammar::FileId(0));
    println!("{:#?}\n{:#?}", f, d);
}
