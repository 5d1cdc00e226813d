//! The interpreter's errors: expressions, parameters, O-word flow control and active
//! comments ([`InterpError`], wrapped in [`crate::ParseErrorKind::Interp`]). Like every parse
//! error they are `Copy` and heap-free, name the value or the name that broke the rule, and
//! say the rule.

use crate::name::Name;
use crate::rules::{MAX_CALL_DEPTH, MAX_EXPR_DEPTH, MAX_PARAMETER};

/// What the interpreter refused.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum InterpError {
    // ---- expressions ---------------------------------------------------------------------
    #[error("`[` is not closed by `]` on this line")]
    UnclosedExpression,
    #[error("expected a value: a number, a parameter (#1, #<name>), an expression in brackets or a function (SIN[30])")]
    ExpectedValue,
    #[error("`{word}` is neither a function (ABS ACOS ASIN ATAN COS EXISTS EXP FIX FUP LN ROUND SIN SQRT TAN) nor a value")]
    UnknownFunction { word: Name },
    #[error("expected an operator (** * / MOD + - EQ NE GT GE LT LE AND OR XOR) or `]`")]
    ExpectedOperator,
    #[error("function {func} needs its argument in brackets: {func}[...]")]
    FunctionBracket { func: &'static str },
    #[error("ATAN is written ATAN[y]/[x]")]
    AtanForm,
    #[error("EXISTS takes one parameter in brackets: EXISTS[#<name>]")]
    ExistsForm,
    #[error("an expression with an operator needs brackets: [#1 + 2]")]
    OperatorOutsideBrackets,
    #[error("expression nested deeper than {MAX_EXPR_DEPTH} brackets, functions or signs")]
    TooDeep,
    #[error("division by zero")]
    DivideByZero,
    #[error("SQRT of a negative number ({value})")]
    NegativeSqrt { value: f64 },
    #[error("LN of zero or a negative number ({value})")]
    LnDomain { value: f64 },
    #[error("{func} of {value}: the argument must be from -1 to 1")]
    InverseTrigDomain { func: &'static str, value: f64 },
    #[error("{base} ** {exponent}: a negative number raised to a power that is not whole")]
    NegativePower { base: f64, exponent: f64 },
    #[error("the expression is not a number (NaN), as MOD by zero gives")]
    NotANumber,
    #[error("the expression overflows to infinity")]
    Infinite,

    // ---- parameters ----------------------------------------------------------------------
    #[error("#{value}: numbered parameters are #1 to #{MAX_PARAMETER}")]
    ParameterOutOfRange { value: f64 },
    #[error("{value} is not a whole number (within 0.0001), as parameter numbers, O-word numbers and loop counts must be")]
    NotWhole { value: f64 },
    #[error("#{number} is read-only: {why}")]
    ReadOnlyParameter { number: u32, why: &'static str },
    #[error("#<{name}> is read-only: names starting with _ and given by the interpreter ({why})")]
    ReadOnlyNamed { name: Name, why: &'static str },
    #[error("#<{name}> is not defined: assign it first (#<{name}> = ...); a name without a leading _ is local to its subroutine")]
    UndefinedNamed { name: Name },
    #[error("#5399: what M66 reads is known only when the machine gets there, and dnurbs plans ahead of the machine (LinuxCNC waits for it)")]
    InputUnknown,
    #[error("#<{name}>: the position is not known before the program's first move")]
    PositionUnknown { name: Name },
    #[error("a named parameter `#<` needs its closing `>`")]
    NameNotClosed,
    #[error("a parameter assignment needs `=` after the parameter: #1 = 5")]
    MissingEquals,
    #[error("more than {most} numbered or {most} named parameter assignments on one line")]
    TooManyAssignments { most: usize },

    // ---- O-words -------------------------------------------------------------------------
    #[error("an O-word needs one of sub endsub call return if elseif else endif while endwhile do repeat endrepeat break continue")]
    UnknownControl,
    #[error("only comments may follow an O-word and its arguments")]
    AfterOWord,
    #[error("o.. {keyword} needs its {what} in brackets: o100 {keyword} [#1 GT 0]")]
    ControlBracket {
        keyword: &'static str,
        what: &'static str,
    },
    #[error("o{label} {keyword}: no o{label} {opens} is open here")]
    UnmatchedLabel {
        label: Name,
        keyword: &'static str,
        opens: &'static str,
    },
    #[error("o{label} {keyword} does not match the o{label} {found} of line {line}")]
    MismatchedLabel {
        label: Name,
        keyword: &'static str,
        found: &'static str,
        line: u32,
    },
    #[error("o{label} {keyword}: the label o{label} is already used by the {found} of line {line} in this scope; labels of if, while, do and repeat are used once per subroutine")]
    DuplicateLabel {
        label: Name,
        keyword: &'static str,
        found: &'static str,
        line: u32,
    },
    #[error("o{label} {keyword} outside a subroutine")]
    NotInSubroutine { label: Name, keyword: &'static str },
    #[error("o{label} sub inside the definition of o{outer}: subroutines do not nest")]
    NestedDefinition { label: Name, outer: Name },
    #[error("o{label} sub: already defined at line {line}")]
    Redefined { label: Name, line: u32 },
    #[error("o{label} sub: the program runs into the definition of a subroutine it already knows; define subroutines before their calls or after M02")]
    DefinitionInTheWay { label: Name },
    #[error("o{label} call: more than 30 arguments")]
    TooManyArguments { label: Name },
    #[error("o{label} call: more than {MAX_CALL_DEPTH} calls nested")]
    TooManyCalls { label: Name },
    #[error("o{label} call: no subroutine o{label} in the program, nor a file {label}.ngc in the subroutine directories")]
    SubroutineNotFound { label: Name },
    #[error("o{label} call: the file {label}.ngc cannot be read ({kind}) or has no o{label} sub")]
    SubroutineFile {
        label: Name,
        kind: std::io::ErrorKind,
    },
    #[error("the program has run {most} lines again in its loops and subroutines, the most a program may (a loop that never ends? the machine file's [program] max_loop_lines sets the limit)")]
    TooManyIterations { most: u64 },
    #[error("the program ends inside o{label} {keyword} of line {line}: its o{label} {closer} is missing")]
    NotClosed {
        label: Name,
        keyword: &'static str,
        closer: &'static str,
        line: u32,
    },

    // ---- comments --------------------------------------------------------------------------
    #[error("aborted by the program: {message}")]
    Abort { message: Name },
    #[error("a comment cannot contain `(`: comments do not nest")]
    NestedComment,
}
