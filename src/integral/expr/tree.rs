//! The expression as a tree: parsed from tokens that passed the grammar
//! check, with the usual precedence (`^` above unary signs above `* /`
//! above `+ -`, each left to right), and its constant parts folded.

use super::ExprError;
use super::lex::{Token, fault};
use super::ops;

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl BinOp {
    /// `a op b`.
    #[inline(always)]
    pub(super) fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            BinOp::Add => a + b,
            BinOp::Sub => a - b,
            BinOp::Mul => a * b,
            BinOp::Div => a / b,
            BinOp::Pow => a.powf(b),
        }
    }
}

/// A node of the tree.
#[derive(Debug, Clone)]
pub(super) enum Node {
    Num(f64),
    /// A variable, by its index in the domain's list.
    Var(usize),
    Neg(Box<Node>),
    Bin(BinOp, Box<Node>, Box<Node>),
    Call1(fn(f64) -> f64, Box<Node>),
    Call2(fn(f64, f64) -> f64, Box<Node>, Box<Node>),
}

/// A recursive-descent parser over checked tokens.
pub(super) struct Parser<'a> {
    pub(super) text: &'a str,
    pub(super) toks: &'a [(Token<'a>, usize)],
    pub(super) variables: &'a [&'a str],
    pub(super) i: usize,
}

impl Parser<'_> {
    /// The whole expression.
    pub(super) fn parse(mut self) -> Result<Node, ExprError> {
        let node = self.sum()?;
        match self.toks.get(self.i) {
            None => Ok(node),
            Some(&(_, at)) => Err(fault(self.text, at, "expected the end here")),
        }
    }

    fn peek(&self) -> Option<Token<'_>> {
        self.toks.get(self.i).map(|t| t.0)
    }

    /// The next token, which must be `want`.
    fn expect(&mut self, want: Token<'_>, what: &str) -> Result<(), ExprError> {
        match self.toks.get(self.i) {
            Some(&(t, _)) if t == want => {
                self.i += 1;
                Ok(())
            }
            Some(&(_, at)) => Err(fault(self.text, at, format!("expected {what} here"))),
            None => Err(fault(
                self.text,
                self.text.len(),
                format!("expected {what}"),
            )),
        }
    }

    /// `product (('+' | '-') product)*`.
    fn sum(&mut self) -> Result<Node, ExprError> {
        let mut lhs = self.product()?;
        while let Some(Token::Op(c @ (b'+' | b'-'))) = self.peek() {
            self.i += 1;
            let op = if c == b'+' { BinOp::Add } else { BinOp::Sub };
            lhs = Node::Bin(op, Box::new(lhs), Box::new(self.product()?));
        }
        Ok(lhs)
    }

    /// `signed (('*' | '/') signed)*`.
    fn product(&mut self) -> Result<Node, ExprError> {
        let mut lhs = self.signed()?;
        while let Some(Token::Op(c @ (b'*' | b'/'))) = self.peek() {
            self.i += 1;
            let op = if c == b'*' { BinOp::Mul } else { BinOp::Div };
            lhs = Node::Bin(op, Box::new(lhs), Box::new(self.signed()?));
        }
        Ok(lhs)
    }

    /// `('-' | '+') signed | power`.
    fn signed(&mut self) -> Result<Node, ExprError> {
        match self.peek() {
            Some(Token::Op(b'-')) => {
                self.i += 1;
                Ok(Node::Neg(Box::new(self.signed()?)))
            }
            Some(Token::Op(b'+')) => {
                self.i += 1;
                self.signed()
            }
            _ => self.power(),
        }
    }

    /// `atom ('^' signed)?`: the check refuses a chain of `^` and a signed
    /// base before one.
    fn power(&mut self) -> Result<Node, ExprError> {
        let base = self.atom()?;
        if self.peek() == Some(Token::Op(b'^')) {
            self.i += 1;
            let exponent = self.signed()?;
            return Ok(Node::Bin(BinOp::Pow, Box::new(base), Box::new(exponent)));
        }
        Ok(base)
    }

    /// A number, a constant, a variable, a call or a group.
    fn atom(&mut self) -> Result<Node, ExprError> {
        let Some(&(tok, at)) = self.toks.get(self.i) else {
            return Err(fault(self.text, self.text.len(), "expected an operand"));
        };
        self.i += 1;
        match tok {
            Token::Number(s) => s
                .parse::<f64>()
                .map(Node::Num)
                .map_err(|_| fault(self.text, at, format!("{s} is not a number"))),
            Token::Open => {
                let inner = self.sum()?;
                self.expect(Token::Close, "`)`")?;
                Ok(inner)
            }
            Token::Name(name) => self.named(name, at),
            _ => Err(fault(self.text, at, "expected an operand here")),
        }
    }

    /// A constant, a variable or a call of `name`.
    fn named(&mut self, name: &str, at: usize) -> Result<Node, ExprError> {
        if let Some(c) = ops::constant(name) {
            return Ok(Node::Num(c));
        }
        if let Some(k) = self.variables.iter().position(|v| *v == name) {
            return Ok(Node::Var(k));
        }
        if let Some(f) = ops::unary(name) {
            self.expect(Token::Open, "`(`")?;
            let a = self.sum()?;
            self.expect(Token::Close, "`)`")?;
            return Ok(Node::Call1(f, Box::new(a)));
        }
        if let Some(f) = ops::binary(name) {
            self.expect(Token::Open, "`(`")?;
            let a = self.sum()?;
            self.expect(Token::Comma, "`,`")?;
            let b = self.sum()?;
            self.expect(Token::Close, "`)`")?;
            return Ok(Node::Call2(f, Box::new(a), Box::new(b)));
        }
        Err(fault(self.text, at, format!("unknown name `{name}`")))
    }
}

impl Node {
    /// The tree with every part free of variables replaced by its value.
    pub(super) fn folded(self) -> Node {
        match self {
            Node::Neg(a) => match a.folded() {
                Node::Num(x) => Node::Num(-x),
                a => Node::Neg(Box::new(a)),
            },
            Node::Bin(op, a, b) => match (a.folded(), b.folded()) {
                (Node::Num(x), Node::Num(y)) => Node::Num(op.apply(x, y)),
                (a, b) => Node::Bin(op, Box::new(a), Box::new(b)),
            },
            Node::Call1(f, a) => match a.folded() {
                Node::Num(x) => Node::Num(f(x)),
                a => Node::Call1(f, Box::new(a)),
            },
            Node::Call2(f, a, b) => match (a.folded(), b.folded()) {
                (Node::Num(x), Node::Num(y)) => Node::Num(f(x, y)),
                (a, b) => Node::Call2(f, Box::new(a), Box::new(b)),
            },
            leaf => leaf,
        }
    }

    /// The variables the tree names, by index.
    pub(super) fn variables(&self, out: &mut Vec<usize>) {
        match self {
            Node::Num(_) => {}
            Node::Var(k) => out.push(*k),
            Node::Neg(a) | Node::Call1(_, a) => a.variables(out),
            Node::Bin(_, a, b) | Node::Call2(_, a, b) => {
                a.variables(out);
                b.variables(out);
            }
        }
    }
}
