//! The parameters a program reads and sets, as LinuxCNC keeps them: numbered ones `#1` to
//! `#5601` (an unset one reads 0; `#1`..`#30` are a subroutine's arguments, saved and
//! restored around each call), global named ones `#<_name>` and named ones local to the
//! subroutine call they were set in `#<name>`.
//!
//! What the interpreter computes from the program's state (the position, the modes, the
//! offsets: `#5220`, `#5400`.., `#5420`.., `#<_x>`.., see `interp.rs`) is not stored here.

use crate::rules::MAX_PARAMETER;
use std::collections::HashMap;

/// Subroutine arguments: `#1`..`#30`.
pub const ARGUMENTS: usize = 30;

/// The parameter store.
#[derive(Clone, Debug)]
pub struct Params {
    numbered: Vec<f64>,
    globals: HashMap<String, f64>,
    /// One map per call level, level 0 the main program.
    locals: Vec<HashMap<String, f64>>,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            numbered: vec![0.0; MAX_PARAMETER as usize + 1],
            globals: HashMap::new(),
            locals: vec![HashMap::new()],
        }
    }
}

impl Params {
    /// Numbered parameter `n` (1..=[`MAX_PARAMETER`], checked by the caller).
    pub fn numbered(&self, n: u32) -> f64 {
        self.numbered.get(n as usize).copied().unwrap_or(0.0)
    }

    pub fn set_numbered(&mut self, n: u32, v: f64) {
        if let Some(slot) = self.numbered.get_mut(n as usize) {
            *slot = v;
        }
    }

    fn scope(&self, name: &str) -> Option<&HashMap<String, f64>> {
        if name.starts_with('_') {
            Some(&self.globals)
        } else {
            self.locals.last()
        }
    }

    /// Named parameter `name` (lower case), if it exists in its scope.
    pub fn named(&self, name: &str) -> Option<f64> {
        self.scope(name).and_then(|s| s.get(name).copied())
    }

    pub fn set_named(&mut self, name: &str, v: f64) {
        let scope = if name.starts_with('_') {
            Some(&mut self.globals)
        } else {
            self.locals.last_mut()
        };
        if let Some(s) = scope {
            s.insert(name.to_owned(), v);
        }
    }

    /// A call: a new level of local names, `#1`.. set to `args` and the rest of `#1`..`#30`
    /// to 0. Returns the caller's `#1`..`#30`, for [`Params::leave`].
    pub fn enter(&mut self, args: &[f64]) -> [f64; ARGUMENTS] {
        let mut saved = [0.0; ARGUMENTS];
        saved.copy_from_slice(&self.numbered[1..=ARGUMENTS]);
        for (k, slot) in self.numbered[1..=ARGUMENTS].iter_mut().enumerate() {
            *slot = args.get(k).copied().unwrap_or(0.0);
        }
        self.locals.push(HashMap::new());
        saved
    }

    /// The return: the level's local names go, the caller's `#1`..`#30` come back.
    pub fn leave(&mut self, saved: &[f64; ARGUMENTS]) {
        self.numbered[1..=ARGUMENTS].copy_from_slice(saved);
        if self.locals.len() > 1 {
            self.locals.pop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locals_are_per_call_and_arguments_are_restored() {
        let mut p = Params::default();
        p.set_numbered(1, 7.0);
        p.set_numbered(40, 1.0);
        p.set_named("x", 3.0);
        p.set_named("_g", 4.0);
        let saved = p.enter(&[5.0]);
        assert_eq!((p.numbered(1), p.numbered(2)), (5.0, 0.0));
        assert_eq!(p.named("x"), None, "a caller's local is not visible");
        assert_eq!(p.named("_g"), Some(4.0));
        p.set_named("y", 1.0);
        p.set_numbered(40, 2.0);
        p.leave(&saved);
        assert_eq!(p.numbered(1), 7.0);
        assert_eq!(p.numbered(40), 2.0, "#31 and up are global");
        assert_eq!(p.named("y"), None);
        assert_eq!(p.named("x"), Some(3.0));
    }
}
