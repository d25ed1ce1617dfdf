//! Choices among a fixed set of named values (samplers, integrators, strategies, tone maps),
//! read from the names a command line, Python or the viewer gives them.

/// The value among `all` whose name is `text` (in any case), or an error that lists the
/// names: `unknown sampler 'x' (expected independent, stratified or sobol)`.
pub fn by_name<T: Copy>(
    text: &str,
    all: &[T],
    name: fn(T) -> &'static str,
    what: &str,
) -> Result<T, String> {
    all.iter()
        .copied()
        .find(|&v| name(v).eq_ignore_ascii_case(text))
        .ok_or_else(|| {
            let names: Vec<&str> = all.iter().map(|&v| name(v)).collect();
            let list = match names.split_last() {
                Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
                _ => names.concat(),
            };
            format!("unknown {what} '{text}' (expected {list})")
        })
}

#[cfg(test)]
mod tests {
    use super::by_name;

    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Fruit {
        Apple,
        Pear,
        Plum,
    }

    fn name(f: Fruit) -> &'static str {
        match f {
            Fruit::Apple => "apple",
            Fruit::Pear => "pear",
            Fruit::Plum => "plum",
        }
    }

    #[test]
    fn names_are_found_in_any_case_and_errors_list_them() {
        let all = [Fruit::Apple, Fruit::Pear, Fruit::Plum];
        assert_eq!(by_name("PEAR", &all, name, "fruit"), Ok(Fruit::Pear));
        assert_eq!(
            by_name("fig", &all, name, "fruit"),
            Err("unknown fruit 'fig' (expected apple, pear or plum)".to_string())
        );
        assert_eq!(
            by_name("fig", &all[..1], name, "fruit"),
            Err("unknown fruit 'fig' (expected apple)".to_string())
        );
    }
}
