//! Where a field path (`road.surface[0].friction`) is written in a map's text, so that
//! a semantic problem names its line and column as a syntax error does.

/// One open bracket: the field path of what it holds, and for a list the index of the
/// item being read.
struct Frame {
    path: String,
    list: Option<usize>,
    key: Option<String>,
}

/// The 1-based line and column where `path` is written in `text` (its key, or for a
/// list item its opening bracket); `None` when the text does not write it (a field
/// inherited from a base, or a default).
pub(crate) fn field(text: &str, path: &str) -> Option<(usize, usize)> {
    if path.is_empty() {
        return None;
    }
    let chars: Vec<char> = text.chars().collect();
    let (mut i, mut line, mut col) = (0usize, 1usize, 1usize);
    let mut stack: Vec<Frame> = Vec::new();
    let advance = |i: &mut usize, line: &mut usize, col: &mut usize| {
        if chars[*i] == '\n' {
            *line += 1;
            *col = 1;
        } else {
            *col += 1;
        }
        *i += 1;
    };
    while i < chars.len() {
        let c = chars[i];
        let at = (line, col);
        if c == '/' && chars.get(i + 1) == Some(&'/') {
            while i < chars.len() && chars[i] != '\n' {
                advance(&mut i, &mut line, &mut col);
            }
            continue;
        }
        if c == '/' && chars.get(i + 1) == Some(&'*') {
            while i < chars.len() && !(chars[i] == '*' && chars.get(i + 1) == Some(&'/')) {
                advance(&mut i, &mut line, &mut col);
            }
            advance(&mut i, &mut line, &mut col);
        } else if c == '"' {
            advance(&mut i, &mut line, &mut col);
            while i < chars.len() && chars[i] != '"' {
                if chars[i] == '\\' {
                    advance(&mut i, &mut line, &mut col);
                }
                if i < chars.len() {
                    advance(&mut i, &mut line, &mut col);
                }
            }
        } else if matches!(c, '(' | '[' | '{') {
            let here = match stack.last_mut() {
                None => String::new(),
                Some(parent) => match (parent.key.take(), parent.list) {
                    (Some(key), _) => join(&parent.path, &key),
                    (None, Some(n)) => format!("{}[{n}]", parent.path),
                    (None, None) => parent.path.clone(),
                },
            };
            if here == path {
                return Some(at);
            }
            stack.push(Frame {
                path: here,
                list: (c == '[').then_some(0),
                key: None,
            });
        } else if matches!(c, ')' | ']' | '}') {
            stack.pop();
        } else if c == ',' {
            if let Some(f) = stack.last_mut() {
                f.key = None;
                if let Some(n) = f.list.as_mut() {
                    *n += 1;
                }
            }
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                advance(&mut i, &mut line, &mut col);
            }
            let word: String = chars[start..i].iter().collect();
            let mut j = i;
            while j < chars.len() && chars[j].is_whitespace() {
                j += 1;
            }
            if chars.get(j) == Some(&':')
                && let Some(f) = stack.last_mut()
                && f.list.is_none()
            {
                let full = join(&f.path, &word);
                if full == path {
                    return Some(at);
                }
                f.key = Some(word);
            }
            continue;
        }
        advance(&mut i, &mut line, &mut col);
    }
    None
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

#[cfg(test)]
mod tests {
    use super::field;

    #[test]
    fn finds_keys_and_list_items() {
        let text = "// a map\nMap(\n    road: Road(friction: 0.0, surface: [\n        (from: 1.0, to: 2.0, friction: 3.0),\n        (from: 1.0, to: 2.0, friction: 3.0),\n    ]),\n    vehicle: (power: 0.0),\n)\n";
        assert_eq!(field(text, "road.friction"), Some((3, 16)));
        assert_eq!(field(text, "road.surface[1]"), Some((5, 9)));
        assert_eq!(field(text, "road.surface[1].friction"), Some((5, 30)));
        assert_eq!(field(text, "vehicle.power"), Some((7, 15)));
        assert_eq!(field(text, "vehicle.mass"), None);
    }
}
