//! The text layer shared by the two CSG dialects read here — the project's
//! OpenSCAD subset ([`super::csg`]) and VisibleSim's ([`super::vs_csg`]):
//! tokens with their line and column, and a cursor over them that reads
//! arithmetic (`+ − * /`, unary signs, parentheses, `sqrt(…)`, named
//! constants where a dialect has them). Each dialect keeps its own
//! grammar of objects and its own way of naming a position.

use crate::error::InputError;

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok {
    Num(f64),
    Id(String),
    Sym(char),
}

/// A token with its 1-based line and column.
pub(super) type Spanned = (Tok, usize, usize);

/// Splits `text` into tokens; `//` starts a comment to the end of the
/// line. A character no dialect uses, or a malformed number, is refused
/// with its line and column.
pub(super) fn lex(text: &str) -> Result<Vec<Spanned>, InputError> {
    let mut out = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let cs: Vec<char> = line.split("//").next().unwrap_or("").chars().collect();
        let mut i = 0;
        while i < cs.len() {
            let c = cs[i];
            let at = (ln + 1, i + 1);
            if c.is_whitespace() {
                i += 1;
            } else if c.is_ascii_digit() || c == '.' {
                let s = i;
                while i < cs.len()
                    && (cs[i].is_ascii_digit()
                        || cs[i] == '.'
                        || cs[i] == 'e'
                        || ((cs[i] == '-' || cs[i] == '+') && i > s && cs[i - 1] == 'e'))
                {
                    i += 1;
                }
                let t: String = cs[s..i].iter().collect();
                let v: f64 = t.parse().map_err(|_| {
                    InputError::new(format!("line {}, column {}: bad number '{t}'", at.0, at.1))
                })?;
                out.push((Tok::Num(v), at.0, at.1));
            } else if c.is_alphabetic() || c == '_' || c == '$' {
                let s = i;
                while i < cs.len() && (cs[i].is_alphanumeric() || cs[i] == '_' || cs[i] == '$') {
                    i += 1;
                }
                out.push((Tok::Id(cs[s..i].iter().collect()), at.0, at.1));
            } else if "()[]{},;=+-*/".contains(c) {
                out.push((Tok::Sym(c), at.0, at.1));
                i += 1;
            } else {
                return Err(InputError::new(format!(
                    "line {}, column {}: unexpected character '{c}'",
                    at.0, at.1
                )));
            }
        }
    }
    Ok(out)
}

/// A text's tokens, the position in them and the current nesting.
#[derive(Debug, Default)]
pub(super) struct Tokens {
    pub toks: Vec<Spanned>,
    pub pos: usize,
    pub depth: usize,
}

impl Tokens {
    pub fn new(toks: Vec<Spanned>) -> Tokens {
        Tokens {
            toks,
            ..Default::default()
        }
    }
    pub fn at_end(&self) -> bool {
        self.pos >= self.toks.len()
    }
}

/// A parser's position in its tokens, and the arithmetic both dialects
/// read. A dialect supplies its tokens, its nesting limit, how it names a
/// position in an error, and its named constants.
pub(super) trait Cursor {
    fn tokens(&self) -> &Tokens;
    fn tokens_mut(&mut self) -> &mut Tokens;
    /// Deepest nesting read: the parsers and the solids' membership tests
    /// recurse, so deeper text is refused rather than overflowing the stack.
    fn max_depth(&self) -> usize;
    /// An error at the current token, named as the dialect names places.
    fn err(&self, msg: impl std::fmt::Display) -> InputError;
    /// The value of a named constant (`None`: not a name of this dialect).
    fn constant(&self, _name: &str) -> Option<f64> {
        None
    }

    /// The (line, column) of the current token, or of the last one at the
    /// end of the text.
    fn here(&self) -> Option<(usize, usize)> {
        let t = self.tokens();
        t.toks.get(t.pos).or(t.toks.last()).map(|t| (t.1, t.2))
    }
    fn peek(&self) -> Option<&Tok> {
        let t = self.tokens();
        t.toks.get(t.pos).map(|t| &t.0)
    }
    fn next_tok(&mut self) -> Option<Tok> {
        let t = self.peek().cloned();
        self.tokens_mut().pos += 1;
        t
    }
    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(&Tok::Sym(c)) {
            self.tokens_mut().pos += 1;
            true
        } else {
            false
        }
    }
    fn expect(&mut self, c: char) -> Result<(), InputError> {
        if self.eat(c) {
            return Ok(());
        }
        let found = self.peek().cloned();
        Err(self.err(format!("expected '{c}', found {found:?}")))
    }
    /// Enters one nesting level, refusing beyond [`Cursor::max_depth`].
    fn deeper(&mut self) -> Result<(), InputError> {
        self.tokens_mut().depth += 1;
        if self.tokens().depth > self.max_depth() {
            let m = self.max_depth();
            return Err(self.err(format!("nested more than {m} levels deep")));
        }
        Ok(())
    }
    fn shallower(&mut self) {
        self.tokens_mut().depth -= 1;
    }

    /// A sum of terms; the value must be finite (a NaN or an infinity is
    /// never a dimension).
    fn expr(&mut self) -> Result<f64, InputError> {
        let mut v = self.term()?;
        loop {
            if self.eat('+') {
                v += self.term()?;
            } else if self.eat('-') {
                v -= self.term()?;
            } else {
                break;
            }
        }
        if !v.is_finite() {
            return Err(self.err("the expression is not a finite number"));
        }
        Ok(v)
    }
    fn term(&mut self) -> Result<f64, InputError> {
        let mut v = self.factor()?;
        loop {
            if self.eat('*') {
                v *= self.factor()?;
            } else if self.eat('/') {
                v /= self.factor()?;
            } else {
                return Ok(v);
            }
        }
    }
    /// A number, a constant, `sqrt(…)`, or a signed or parenthesised
    /// factor (the recursive cases count as a nesting level).
    fn factor(&mut self) -> Result<f64, InputError> {
        if matches!(self.peek(), Some(Tok::Sym('-' | '+' | '('))) {
            self.deeper()?;
            let v = self.factor_inner();
            self.shallower();
            v
        } else {
            self.factor_inner()
        }
    }
    fn factor_inner(&mut self) -> Result<f64, InputError> {
        match self.peek().cloned() {
            Some(Tok::Num(v)) => {
                self.next_tok();
                Ok(v)
            }
            Some(Tok::Sym('-')) => {
                self.next_tok();
                Ok(-self.factor()?)
            }
            Some(Tok::Sym('+')) => {
                self.next_tok();
                self.factor()
            }
            Some(Tok::Sym('(')) => {
                self.next_tok();
                let v = self.expr()?;
                self.expect(')')?;
                Ok(v)
            }
            Some(Tok::Id(f)) if f == "sqrt" => {
                self.next_tok();
                self.expect('(')?;
                let v = self.expr()?;
                self.expect(')')?;
                Ok(v.sqrt())
            }
            Some(Tok::Id(n)) => match self.constant(&n) {
                Some(v) => {
                    self.next_tok();
                    Ok(v)
                }
                None => Err(self.err(format!("unknown name '{n}'"))),
            },
            other => Err(self.err(format!("expected a number, found {other:?}"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Bare(Tokens);

    impl Cursor for Bare {
        fn tokens(&self) -> &Tokens {
            &self.0
        }
        fn tokens_mut(&mut self) -> &mut Tokens {
            &mut self.0
        }
        fn max_depth(&self) -> usize {
            10
        }
        fn err(&self, msg: impl std::fmt::Display) -> InputError {
            let (l, c) = self.here().unwrap_or((0, 0));
            InputError::new(format!("line {l}, column {c}: {msg}"))
        }
    }

    fn eval(text: &str) -> Result<f64, InputError> {
        Bare(Tokens::new(lex(text)?)).expr()
    }

    #[test]
    fn arithmetic_has_the_usual_precedence_and_signs() {
        assert_eq!(eval("1 + 2 * 3").unwrap(), 7.0);
        assert_eq!(eval("(1 + 2) * 3").unwrap(), 9.0);
        assert_eq!(eval("-2 * -3 + +1").unwrap(), 7.0);
        assert_eq!(
            eval("sqrt(2) * sqrt(2) / 2").unwrap(),
            2.0_f64.sqrt().powi(2) / 2.0
        );
        assert_eq!(eval("1.5e-1 + .5").unwrap(), 0.65);
    }

    #[test]
    fn a_non_finite_value_an_unknown_name_and_deep_nesting_are_refused_with_their_place() {
        let e = eval("1 / 0").unwrap_err().to_string();
        assert!(e.contains("not a finite number"), "{e}");
        let e = eval("\n  2 * r").unwrap_err().to_string();
        assert!(
            e.contains("line 2, column 7") && e.contains("unknown name 'r'"),
            "{e}"
        );
        let e = eval(&format!("{}1{}", "(".repeat(20), ")".repeat(20))).unwrap_err();
        assert!(e.to_string().contains("nested more than 10"), "{e}");
        let e = lex("1 # 2").unwrap_err().to_string();
        assert!(e.contains("column 3") && e.contains("'#'"), "{e}");
    }
}
