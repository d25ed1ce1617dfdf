//! pbrt's tokens: bare words (directives, numbers, `true`/`false`), quoted strings with
//! escapes, and `[`/`]`; `#` starts a comment to the end of the line. Tokens borrow the file's
//! text; the lexer holds no copies.

use crate::Error;
use std::borrow::Cow;

/// One token and the line it starts on.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token<'a> {
    /// What was read.
    pub kind: TokenKind<'a>,
    /// Line, from 1.
    pub line: usize,
}

/// The kinds of token.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum TokenKind<'a> {
    /// An unquoted word: a directive name, a number, `true` or `false`.
    Word(&'a str),
    /// A quoted string, escapes resolved (borrowed when it has none).
    Str(Cow<'a, str>),
    /// `[`.
    Open,
    /// `]`.
    Close,
}

/// Splits pbrt text into tokens, one at a time.
pub(crate) struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
    file: &'a str,
    /// A token read ahead and given back.
    peeked: Option<Token<'a>>,
}

impl<'a> Lexer<'a> {
    /// A lexer over `text`, from `file` (for messages).
    pub(crate) fn new(text: &'a str, file: &'a str) -> Self {
        Lexer {
            text,
            pos: 0,
            line: 1,
            file,
            peeked: None,
        }
    }

    /// An error at `line` of this file.
    pub(crate) fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::Parse {
            path: self.file.to_string(),
            line,
            column: 0,
            message: message.into(),
        }
    }

    /// Gives `t` back: the next call to [`Lexer::next`] returns it.
    pub(crate) fn unread(&mut self, t: Token<'a>) {
        self.peeked = Some(t);
    }

    /// The next token, `None` at the end of the text.
    #[allow(clippy::should_implement_trait)]
    pub(crate) fn next(&mut self) -> Result<Option<Token<'a>>, Error> {
        if let Some(t) = self.peeked.take() {
            return Ok(Some(t));
        }
        let bytes = self.text.as_bytes();
        // Whitespace and comments.
        loop {
            match bytes.get(self.pos) {
                None => return Ok(None),
                Some(b'\n') => {
                    self.line += 1;
                    self.pos += 1;
                }
                Some(c) if c.is_ascii_whitespace() => self.pos += 1,
                Some(b'#') => {
                    while let Some(&c) = bytes.get(self.pos) {
                        if c == b'\n' {
                            break;
                        }
                        self.pos += 1;
                    }
                }
                Some(_) => break,
            }
        }
        let line = self.line;
        let start = self.pos;
        let kind = match bytes[start] {
            b'[' => {
                self.pos += 1;
                TokenKind::Open
            }
            b']' => {
                self.pos += 1;
                TokenKind::Close
            }
            b'"' => self.string(line)?,
            _ => {
                while let Some(&c) = bytes.get(self.pos) {
                    if c.is_ascii_whitespace() || matches!(c, b'[' | b']' | b'"' | b'#') {
                        break;
                    }
                    self.pos += 1;
                }
                TokenKind::Word(&self.text[start..self.pos])
            }
        };
        Ok(Some(Token { kind, line }))
    }

    /// A quoted string starting at `self.pos` (its opening quote).
    fn string(&mut self, line: usize) -> Result<TokenKind<'a>, Error> {
        let bytes = self.text.as_bytes();
        let start = self.pos + 1;
        let mut i = start;
        let mut escaped = false;
        loop {
            match bytes.get(i) {
                None => return Err(self.error(line, "a string that never ends (missing \")")),
                Some(b'\n') => {
                    return Err(self.error(line, "a string that runs past the end of its line"))
                }
                Some(b'\\') => {
                    escaped = true;
                    i += 2;
                }
                Some(b'"') => break,
                Some(_) => i += 1,
            }
        }
        self.pos = i + 1;
        let raw = &self.text[start..i];
        if !escaped {
            return Ok(TokenKind::Str(Cow::Borrowed(raw)));
        }
        let mut out = String::with_capacity(raw.len());
        let mut chars = raw.chars();
        while let Some(c) = chars.next() {
            if c != '\\' {
                out.push(c);
                continue;
            }
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some('r') => out.push('\r'),
                Some('b') => out.push('\u{8}'),
                Some('f') => out.push('\u{c}'),
                Some(c @ ('\\' | '"' | '\'')) => out.push(c),
                Some(c) => {
                    return Err(self.error(line, format!("unknown escape '\\{c}' in a string")))
                }
                None => return Err(self.error(line, "a string ending in a lone '\\'")),
            }
        }
        Ok(TokenKind::Str(Cow::Owned(out)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<TokenKind<'_>> {
        let mut l = Lexer::new(text, "t.pbrt");
        let mut out = Vec::new();
        while let Some(t) = l.next().unwrap() {
            out.push(t.kind);
        }
        out
    }

    #[test]
    fn words_strings_brackets_and_comments() {
        let k = kinds("Shape \"sphere\" # a comment [\n \"float radius\" [ 2.5 ]\"a\\\"b\"");
        assert_eq!(
            k,
            vec![
                TokenKind::Word("Shape"),
                TokenKind::Str("sphere".into()),
                TokenKind::Str("float radius".into()),
                TokenKind::Open,
                TokenKind::Word("2.5"),
                TokenKind::Close,
                TokenKind::Str("a\"b".into()),
            ]
        );
        let mut l = Lexer::new("A\n\n  B", "t.pbrt");
        assert_eq!(l.next().unwrap().unwrap().line, 1);
        assert_eq!(l.next().unwrap().unwrap().line, 3);
        assert!(Lexer::new("\"open", "t.pbrt").next().is_err());
        assert!(Lexer::new("\"a\\q\"", "t.pbrt").next().is_err());
    }
}
