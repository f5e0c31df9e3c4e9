//! Bracketed parametric L-systems as Qin and Chen 2006 §2–§3
//! writes them: an axiom, productions rewritten in parallel for a number
//! of derivation steps, and named constants.
//!
//! The text, one statement per line (blank lines are skipped):
//!
//! ```text
//! initial line width = 20        (a constant: NAME = number)
//! lenA = 500
//! axiom: /(154) &(72) #A!B       (or `ω:`)
//! p1: B -> D/(60)D/(60)D         (an optional label, `->` or `→`)
//! A(x) -> F(x) A(x * 0.9)        (formal parameters, used in expressions)
//! name A = stem                  (what the tubes module A writes are called)
//! ```
//!
//! A module is one character (a letter, or a turtle symbol
//! `F f + - & ^ / \ [ ] # ! ;`), `~` followed by the letter of a surface, each
//! optionally followed by parameters in parentheses: arithmetic expressions
//! (`+ - * /`, unary minus, parentheses, numbers, constants and, in a
//! production's successor, its formal parameters). Spaces between modules
//! are ignored. Constant names may contain spaces (`initial line width`);
//! the turtle's defaults are the constants `angle` (degrees, default 90),
//! `step` (1), `initial line width` or `width` (1), `line width increment`
//! or `width increment` (1) and `scale` (1).
//!
//! `name X = word` (a module letter, then a name of ASCII letters, digits
//! and `_` starting with a letter) names the tubes the `F`s derived from
//! module `X` draw: each `F` of the derived word remembers the modules it
//! was rewritten from ([`LSystem::derive_with_origins`]), and its tube is
//! called after the nearest of them that has a name (`name S = stamen`
//! with `S → F[-F][+F]`: three stamens per `S`). Without one, after the
//! letter of the module whose production wrote it; an `F` of the axiom is a
//! `segment`. See [`super::Structure::tubes`] for the numbering.

use std::collections::BTreeMap;

use thiserror::Error;

/// The most modules a derived word may hold; a system that grows past it
/// is refused (a file from a stranger must not exhaust the memory).
pub const MAX_MODULES: usize = 1_000_000;

/// The most derivation steps asked for (real flowers need a handful).
pub const MAX_STEPS: u32 = 100;

/// The most terms (numbers, names, signs and parentheses) one parameter
/// expression may hold: deeper nesting would exhaust the stack.
pub const MAX_EXPRESSION_TERMS: usize = 256;

/// A syntax error, or a word that grows too long.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LSystemError {
    /// The text does not follow the syntax; `line` and `column` count from
    /// 1 (columns in characters).
    #[error("L-system line {line}, column {column}: expected {expected}, found {found}")]
    Syntax {
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// What the parser wanted there.
        expected: String,
        /// What it found (a quoted character or "the end of the line").
        found: String,
    },
    /// A statement is missing or said twice.
    #[error("L-system: {0}")]
    Statement(String),
    /// A name in an expression is neither a constant nor a parameter.
    #[error("L-system line {line}: `{name}` is not a constant or a parameter")]
    UnknownName {
        /// 1-based line of the statement.
        line: usize,
        /// The name.
        name: String,
    },
    /// A module was rewritten with fewer parameters than its production
    /// names.
    #[error(
        "L-system: module {symbol} has {given} parameters but the production on line {line} needs {needed}"
    )]
    Arity {
        /// The module's symbol.
        symbol: String,
        /// Parameters it has.
        given: usize,
        /// Parameters the production names.
        needed: usize,
        /// 1-based line of the production.
        line: usize,
    },
    /// A number or a parameter that is not finite (`0/0`, `1/0`, `NaN`):
    /// the turtle would place organs nowhere. `column` counts from 1.
    #[error("L-system line {line}, column {column}: `{text}` is {value}, not a finite number")]
    NotFinite {
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// The expression or number as written.
        text: String,
        /// What it evaluates to (NaN, inf or -inf).
        value: f64,
    },
    /// A production gives a module a parameter that is not finite at a
    /// derivation step (`A(x) -> A(x / 0)`).
    #[error(
        "L-system line {line}: the production gives module {symbol} the parameter {value} at derivation step {step}, not a finite number"
    )]
    NotFiniteAt {
        /// 1-based line of the production.
        line: usize,
        /// The module given it.
        symbol: String,
        /// The value (NaN, inf or -inf).
        value: f64,
        /// 1-based derivation step.
        step: u32,
    },
    /// An expression with more terms than [`MAX_EXPRESSION_TERMS`].
    #[error(
        "L-system line {line}, column {column}: an expression may hold at most {MAX_EXPRESSION_TERMS} terms"
    )]
    TooComplex {
        /// 1-based line.
        line: usize,
        /// 1-based column where the expression starts.
        column: usize,
    },
    /// More derivation steps than [`MAX_STEPS`] were asked for.
    #[error("the L-system asks for {0} derivation steps; at most {MAX_STEPS} are allowed")]
    TooManySteps(u32),
    /// The derived word became too long.
    #[error("the L-system grows past {MAX_MODULES} modules at derivation step {step}")]
    TooLong {
        /// 1-based derivation step.
        step: u32,
    },
}

/// A module of a derived word: a symbol and its parameter values.
#[derive(Debug, Clone, PartialEq)]
pub struct Module {
    /// One character, or `~X` for a surface.
    pub symbol: String,
    /// Parameter values.
    pub params: Vec<f64>,
}

/// An arithmetic expression of a production's successor.
#[derive(Debug, Clone, PartialEq)]
enum Expr {
    Number(f64),
    /// Index of a formal parameter.
    Param(usize),
    Neg(Box<Expr>),
    Binary(char, Box<Expr>, Box<Expr>),
}

impl Expr {
    /// Whether the expression reads a formal parameter (else it is a
    /// constant, known when parsed).
    fn has_param(&self) -> bool {
        match self {
            Expr::Number(_) => false,
            Expr::Param(_) => true,
            Expr::Neg(e) => e.has_param(),
            Expr::Binary(_, a, b) => a.has_param() || b.has_param(),
        }
    }

    fn eval(&self, args: &[f64]) -> f64 {
        match self {
            Expr::Number(v) => *v,
            Expr::Param(i) => args.get(*i).copied().unwrap_or(0.0),
            Expr::Neg(e) => -e.eval(args),
            Expr::Binary(op, a, b) => {
                let (a, b) = (a.eval(args), b.eval(args));
                match op {
                    '+' => a + b,
                    '-' => a - b,
                    '*' => a * b,
                    _ => a / b,
                }
            }
        }
    }
}

/// A module of a successor, with expressions for parameters.
#[derive(Debug, Clone, PartialEq)]
struct Template {
    symbol: String,
    params: Vec<Expr>,
}

/// `predecessor(formals) -> successor`.
#[derive(Debug, Clone, PartialEq)]
struct Production {
    symbol: String,
    formals: Vec<String>,
    successor: Vec<Template>,
    line: usize,
}

/// Where a module of a derived word comes from
/// ([`LSystem::derive_with_origins`]): indices into the productions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Origin {
    /// The production that wrote the module (`None`: it is the axiom's).
    producer: Option<u32>,
    /// The production of the nearest module it was rewritten from that has
    /// a `name` (the producer's predecessor, or that module's, …).
    named: Option<u32>,
}

/// A parsed L-system.
#[derive(Debug, Clone, PartialEq)]
pub struct LSystem {
    /// Constants by name (lower case, single spaces).
    pub constants: BTreeMap<String, f64>,
    /// What the tubes derived from a module are called, by the module's
    /// letter (`name S = stamen`).
    pub names: BTreeMap<String, String>,
    /// The axiom, its parameters evaluated.
    pub axiom: Vec<Module>,
    productions: Vec<Production>,
}

impl LSystem {
    /// Parses the text (see the module documentation).
    pub fn parse(text: &str) -> Result<LSystem, LSystemError> {
        let mut constants = BTreeMap::new();
        let mut names = BTreeMap::new();
        let mut axiom: Option<(usize, &str)> = None;
        let mut production_lines = Vec::new();
        for (index, line) in text.lines().enumerate() {
            let number = index + 1;
            let trimmed = line.trim();
            if trimmed.is_empty() {
                continue;
            }
            if let Some((letter, name)) = name_statement(trimmed) {
                if !valid_name(name) {
                    return Err(syntax(
                        number,
                        column_of(line, name),
                        "a name of ASCII letters, digits and `_` starting with a letter (at most 64)",
                        first_char(name),
                    ));
                }
                if names.insert(letter.to_string(), name.to_owned()).is_some() {
                    return Err(LSystemError::Statement(format!(
                        "module {letter} is named a second time on line {number}"
                    )));
                }
            } else if let Some((name, value)) = constant(trimmed) {
                let column = column_of(line, value.trim());
                let value = value
                    .trim()
                    .parse::<f64>()
                    .map_err(|_| syntax(number, column, "a number", first_char(value.trim())))?;
                if !value.is_finite() {
                    return Err(LSystemError::NotFinite {
                        line: number,
                        column,
                        text: line
                            .trim()
                            .rsplit('=')
                            .next()
                            .unwrap_or("")
                            .trim()
                            .escape_debug()
                            .to_string(),
                        value,
                    });
                }
                constants.insert(name, value);
            } else if let Some(rest) = strip_label(trimmed, &["axiom", "ω"]) {
                if axiom.is_some() {
                    return Err(LSystemError::Statement(format!(
                        "a second axiom on line {number}"
                    )));
                }
                axiom = Some((number, rest));
            } else {
                production_lines.push((number, line));
            }
        }
        let (axiom_line, axiom_text) = axiom
            .ok_or_else(|| LSystemError::Statement("no axiom (a line `axiom: WORD`)".to_owned()))?;
        let full = line_of(text, axiom_line);
        let start = full.chars().count() - axiom_text.chars().count();
        let axiom_templates = Parser::new(axiom_line, full, start, None).word(&constants, &[])?;
        let axiom = axiom_templates
            .iter()
            .map(|t| Module {
                symbol: t.symbol.clone(),
                params: t.params.iter().map(|e| e.eval(&[])).collect(),
            })
            .collect();
        let mut productions = Vec::new();
        for (number, line) in production_lines {
            productions.push(parse_production(number, line, &constants)?);
        }
        Ok(LSystem {
            constants,
            names,
            axiom,
            productions,
        })
    }

    /// The word after `steps` parallel rewritings of the axiom: every
    /// module with a production (the first whose symbol matches) is
    /// replaced by its successor, evaluated with the module's parameters;
    /// the others are kept.
    pub fn derive(&self, steps: u32) -> Result<Vec<Module>, LSystemError> {
        self.derive_with_origins(steps).map(|(word, _)| word)
    }

    /// [`LSystem::derive`], and for each module of the word where it comes
    /// from: the production that wrote it and the nearest module it was
    /// rewritten from that has a `name` ([`LSystem::name_of`]).
    pub fn derive_with_origins(
        &self,
        steps: u32,
    ) -> Result<(Vec<Module>, Vec<Origin>), LSystemError> {
        if steps > MAX_STEPS {
            return Err(LSystemError::TooManySteps(steps));
        }
        let mut word = self.axiom.clone();
        let mut origins = vec![Origin::default(); word.len()];
        for step in 1..=steps {
            let mut next = Vec::with_capacity(word.len());
            let mut next_origins = Vec::with_capacity(word.len());
            for (module, origin) in word.iter().zip(&origins) {
                let found = self
                    .productions
                    .iter()
                    .enumerate()
                    .find(|(_, p)| p.symbol == module.symbol);
                match found {
                    Some((index, p)) => {
                        if module.params.len() < p.formals.len() {
                            return Err(LSystemError::Arity {
                                symbol: module.symbol.clone(),
                                given: module.params.len(),
                                needed: p.formals.len(),
                                line: p.line,
                            });
                        }
                        // One production per line of text: far fewer than u32::MAX.
                        let index = index as u32;
                        let child = Origin {
                            producer: Some(index),
                            named: if self.names.contains_key(&p.symbol) {
                                Some(index)
                            } else {
                                origin.named
                            },
                        };
                        for t in &p.successor {
                            let params: Vec<f64> =
                                t.params.iter().map(|e| e.eval(&module.params)).collect();
                            if let Some(&value) = params.iter().find(|v| !v.is_finite()) {
                                return Err(LSystemError::NotFiniteAt {
                                    line: p.line,
                                    symbol: t.symbol.clone(),
                                    value,
                                    step,
                                });
                            }
                            next.push(Module {
                                symbol: t.symbol.clone(),
                                params,
                            });
                            next_origins.push(child);
                        }
                    }
                    None => {
                        next.push(module.clone());
                        next_origins.push(*origin);
                    }
                }
                if next.len() > MAX_MODULES {
                    return Err(LSystemError::TooLong { step });
                }
            }
            word = next;
            origins = next_origins;
        }
        Ok((word, origins))
    }

    /// What a module that came from `origin` draws is called: the `name` of
    /// the nearest module it was rewritten from that has one, else the
    /// letter of the module whose production wrote it, else (a module of
    /// the axiom) `segment`.
    pub fn name_of(&self, origin: Origin) -> &str {
        let symbol = |index: Option<u32>| {
            index
                .and_then(|i| self.productions.get(i as usize))
                .map(|p| p.symbol.as_str())
        };
        if let Some(name) = symbol(origin.named).and_then(|s| self.names.get(s)) {
            return name;
        }
        symbol(origin.producer).unwrap_or("segment")
    }

    /// A constant by name (case and spacing as in [`constant_key`]).
    pub fn constant(&self, name: &str) -> Option<f64> {
        self.constants.get(&constant_key(name)).copied()
    }
}

/// How constant names are compared: lower case, runs of spaces and `_` as
/// one space.
pub fn constant_key(name: &str) -> String {
    name.split(|c: char| c.is_whitespace() || c == '_')
        .filter(|w| !w.is_empty())
        .map(str::to_lowercase)
        .collect::<Vec<_>>()
        .join(" ")
}

/// `NAME = value` where NAME is words of letters, digits, `_` and spaces
/// starting with a letter (so `p1: B -> ...` is not one).
fn constant(line: &str) -> Option<(String, &str)> {
    let (name, value) = line.split_once('=')?;
    let name = name.trim();
    let ok = name.chars().next().is_some_and(char::is_alphabetic)
        && name
            .chars()
            .all(|c| c.is_alphanumeric() || c == '_' || c == ' ');
    ok.then(|| (constant_key(name), value))
}

/// `name X = word`: a module letter and the name its tubes get (checked
/// by [`valid_name`]); the value is what follows `=`, trimmed.
fn name_statement(line: &str) -> Option<(char, &str)> {
    let rest = line.strip_prefix("name")?;
    let (letter, value) = rest.split_once('=')?;
    let mut letters = letter.trim().chars();
    let (Some(letter), None) = (letters.next(), letters.next()) else {
        return None;
    };
    let value = value.trim();
    // `name x = 2` is a constant called "name x".
    (rest.starts_with(char::is_whitespace)
        && letter.is_alphabetic()
        && value.parse::<f64>().is_err())
    .then_some((letter, value))
}

/// A name a tube may get: ASCII letters, digits and `_`, starting with a
/// letter, at most 64 characters (a valid identifier in every export).
fn valid_name(name: &str) -> bool {
    name.len() <= 64
        && name.starts_with(|c: char| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

fn strip_label<'a>(line: &'a str, labels: &[&str]) -> Option<&'a str> {
    let (label, rest) = line.split_once(':')?;
    labels
        .iter()
        .any(|l| label.trim().eq_ignore_ascii_case(l))
        .then_some(rest)
}

fn line_of(text: &str, number: usize) -> &str {
    text.lines().nth(number - 1).unwrap_or("")
}

fn column_of(line: &str, part: &str) -> usize {
    match line.find(part) {
        Some(byte) => line[..byte].chars().count() + 1,
        None => 1,
    }
}

fn first_char(s: &str) -> String {
    s.chars().next().map_or_else(
        || "the end of the line".to_owned(),
        |c| format!("`{}`", c.escape_debug()),
    )
}

fn syntax(line: usize, column: usize, expected: &str, found: String) -> LSystemError {
    LSystemError::Syntax {
        line,
        column,
        expected: expected.to_owned(),
        found,
    }
}

fn parse_production(
    number: usize,
    line: &str,
    constants: &BTreeMap<String, f64>,
) -> Result<Production, LSystemError> {
    let chars: Vec<char> = line.chars().collect();
    let arrow = (0..chars.len()).find_map(|i| {
        if chars[i] == '→' {
            Some((i, 1))
        } else if chars[i] == '-' && chars.get(i + 1) == Some(&'>') {
            Some((i, 2))
        } else {
            None
        }
    });
    let Some((at, len)) = arrow else {
        return Err(syntax(
            number,
            chars.len() + 1,
            "`->` (a production), `axiom:` or `NAME = number`",
            "the end of the line".to_owned(),
        ));
    };
    // An optional label `p1:` before the predecessor.
    let start = chars[..at]
        .iter()
        .position(|&c| c == ':')
        .map_or(0, |c| c + 1);
    let mut left = Parser::new(number, line, start, Some(at));
    left.skip_spaces();
    let symbol = left.symbol()?;
    let mut formals = Vec::new();
    if left.peek() == Some('(') {
        left.pos += 1;
        loop {
            left.skip_spaces();
            formals.push(left.name()?);
            left.skip_spaces();
            match left.peek() {
                Some(',') => left.pos += 1,
                Some(')') => {
                    left.pos += 1;
                    break;
                }
                other => return Err(left.error("`,` or `)`", other)),
            }
        }
    }
    left.skip_spaces();
    if let Some(c) = left.peek() {
        return Err(left.error("`->`", Some(c)));
    }
    let successor = Parser::new(number, line, at + len, None).word(constants, &formals)?;
    Ok(Production {
        symbol,
        formals,
        successor,
        line: number,
    })
}

/// The characters a module symbol may be, besides letters.
const TURTLE_SYMBOLS: &str = "+-&^/\\[]#!;";

/// One level of the expression grammar: parses an operand.
type Operand = fn(&mut Parser, &BTreeMap<String, f64>, &[String]) -> Result<Expr, LSystemError>;

/// A cursor over one line's characters, from `pos` to `end`.
struct Parser {
    line: usize,
    chars: Vec<char>,
    pos: usize,
    end: usize,
    /// Terms of the expression being read, against
    /// [`MAX_EXPRESSION_TERMS`].
    terms: usize,
    /// Where that expression starts (0-based).
    expression_start: usize,
}

impl Parser {
    fn new(line: usize, text: &str, start: usize, end: Option<usize>) -> Parser {
        let chars: Vec<char> = text.chars().collect();
        let end = end.unwrap_or(chars.len());
        Parser {
            line,
            chars,
            pos: start,
            end,
            terms: 0,
            expression_start: start,
        }
    }

    fn peek(&self) -> Option<char> {
        (self.pos < self.end).then(|| self.chars[self.pos])
    }

    fn skip_spaces(&mut self) {
        while self.peek().is_some_and(char::is_whitespace) {
            self.pos += 1;
        }
    }

    fn error(&self, expected: &str, found: Option<char>) -> LSystemError {
        syntax(
            self.line,
            self.pos + 1,
            expected,
            found.map_or_else(
                || "the end of the line".to_owned(),
                |c| format!("`{}`", c.escape_debug()),
            ),
        )
    }

    /// A module symbol: a letter, a turtle symbol, or `~` and a letter.
    fn symbol(&mut self) -> Result<String, LSystemError> {
        match self.peek() {
            Some('~') => {
                self.pos += 1;
                match self.peek() {
                    Some(c) if c.is_alphabetic() => {
                        self.pos += 1;
                        Ok(format!("~{c}"))
                    }
                    other => Err(self.error("the letter of a surface after `~`", other)),
                }
            }
            Some(c) if c.is_alphabetic() || TURTLE_SYMBOLS.contains(c) => {
                self.pos += 1;
                Ok(c.to_string())
            }
            other => Err(self.error(
                "a module (a letter or one of + - & ^ / \\ [ ] # ! ; ~)",
                other,
            )),
        }
    }

    /// A name: a letter then letters, digits and `_`.
    fn name(&mut self) -> Result<String, LSystemError> {
        let start = self.pos;
        match self.peek() {
            Some(c) if c.is_alphabetic() => self.pos += 1,
            other => return Err(self.error("a name", other)),
        }
        while self.peek().is_some_and(|c| c.is_alphanumeric() || c == '_') {
            self.pos += 1;
        }
        Ok(self.chars[start..self.pos].iter().collect())
    }

    /// Modules up to the end.
    fn word(
        &mut self,
        constants: &BTreeMap<String, f64>,
        formals: &[String],
    ) -> Result<Vec<Template>, LSystemError> {
        let mut modules = Vec::new();
        loop {
            self.skip_spaces();
            if self.peek().is_none() {
                return Ok(modules);
            }
            let symbol = self.symbol()?;
            let mut params = Vec::new();
            self.skip_spaces();
            if self.peek() == Some('(') {
                self.pos += 1;
                loop {
                    self.skip_spaces();
                    let start = self.pos;
                    self.terms = 0;
                    self.expression_start = start;
                    let expression = self.expression(constants, formals)?;
                    if !expression.has_param() {
                        let value = expression.eval(&[]);
                        if !value.is_finite() {
                            return Err(LSystemError::NotFinite {
                                line: self.line,
                                column: start + 1,
                                text: self.chars[start..self.pos]
                                    .iter()
                                    .collect::<String>()
                                    .trim()
                                    .escape_debug()
                                    .to_string(),
                                value,
                            });
                        }
                    }
                    params.push(expression);
                    self.skip_spaces();
                    match self.peek() {
                        Some(',') => self.pos += 1,
                        Some(')') => {
                            self.pos += 1;
                            break;
                        }
                        other => return Err(self.error("`,`, `)` or an operator", other)),
                    }
                }
            }
            modules.push(Template { symbol, params });
        }
    }

    /// sum := product (('+' | '-') product)*
    fn expression(
        &mut self,
        constants: &BTreeMap<String, f64>,
        formals: &[String],
    ) -> Result<Expr, LSystemError> {
        self.left_associative(['+', '-'], constants, formals, Parser::product)
    }

    /// product := factor (('*' | '/') factor)*
    fn product(
        &mut self,
        constants: &BTreeMap<String, f64>,
        formals: &[String],
    ) -> Result<Expr, LSystemError> {
        self.left_associative(['*', '/'], constants, formals, Parser::factor)
    }

    /// operand (op operand)* for the two operators `ops`, left to right.
    fn left_associative(
        &mut self,
        ops: [char; 2],
        constants: &BTreeMap<String, f64>,
        formals: &[String],
        operand: Operand,
    ) -> Result<Expr, LSystemError> {
        let mut left = operand(self, constants, formals)?;
        loop {
            self.skip_spaces();
            match self.peek() {
                Some(op) if ops.contains(&op) => {
                    self.pos += 1;
                    let right = operand(self, constants, formals)?;
                    left = Expr::Binary(op, Box::new(left), Box::new(right));
                }
                _ => return Ok(left),
            }
        }
    }

    /// factor := number | name | '-' factor | '(' sum ')'
    fn factor(
        &mut self,
        constants: &BTreeMap<String, f64>,
        formals: &[String],
    ) -> Result<Expr, LSystemError> {
        self.terms += 1;
        if self.terms > MAX_EXPRESSION_TERMS {
            return Err(LSystemError::TooComplex {
                line: self.line,
                column: self.expression_start + 1,
            });
        }
        self.skip_spaces();
        match self.peek() {
            Some('-') => {
                self.pos += 1;
                Ok(Expr::Neg(Box::new(self.factor(constants, formals)?)))
            }
            Some('(') => {
                self.pos += 1;
                let inner = self.expression(constants, formals)?;
                self.skip_spaces();
                match self.peek() {
                    Some(')') => {
                        self.pos += 1;
                        Ok(inner)
                    }
                    other => Err(self.error("`)`", other)),
                }
            }
            Some(c) if c.is_ascii_digit() || c == '.' => {
                let start = self.pos;
                while self
                    .peek()
                    .is_some_and(|c| c.is_ascii_digit() || c == '.' || c == 'e' || c == 'E')
                {
                    self.pos += 1;
                }
                let text: String = self.chars[start..self.pos].iter().collect();
                text.parse::<f64>()
                    .map(Expr::Number)
                    .map_err(|_| syntax(self.line, start + 1, "a number", format!("`{text}`")))
            }
            Some(c) if c.is_alphabetic() => {
                let name = self.name()?;
                if let Some(i) = formals.iter().position(|f| *f == name) {
                    Ok(Expr::Param(i))
                } else if let Some(v) = constants.get(&constant_key(&name)) {
                    Ok(Expr::Number(*v))
                } else {
                    Err(LSystemError::UnknownName {
                        line: self.line,
                        name,
                    })
                }
            }
            other => Err(self.error("a number, a name, `-` or `(`", other)),
        }
    }
}
