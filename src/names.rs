//! Type and system names for people: `std::any::type_name` and bevy's system names carry
//! every module path, which summaries, `magsep info` and messages drop.

/// A system's name without module paths, also inside generics:
/// `a::clear_contribution<b::PullForce>` gives `clear_contribution<PullForce>`.
///
/// ```
/// assert_eq!(magsep::names::short_name("a::f<b::X>"), "f<X>");
/// ```
pub fn short_name(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let mut ident = String::new();
    for c in name.chars() {
        match c {
            ':' => ident.clear(),
            c if c.is_alphanumeric() || c == '_' => ident.push(c),
            c => {
                out.push_str(&ident);
                ident.clear();
                out.push(c);
            }
        }
    }
    out + &ident
}

#[cfg(test)]
#[test]
fn system_names_lose_their_paths_inside_generics_too() {
    assert_eq!(
        short_name("magsep_systems::forces::clear_contribution<myext::pull::PullForce>"),
        "clear_contribution<PullForce>"
    );
    assert_eq!(short_name("advance_clock"), "advance_clock");
    assert_eq!(short_name("a::f<b::X, c::Y<d::Z>>"), "f<X, Y<Z>>");
}
