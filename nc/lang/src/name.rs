//! [`Name`]: a parameter or subroutine name carried by value in an error, so that errors
//! stay `Copy`, small and heap-free. Names are as the language reads them: lower case, spaces
//! removed. A name longer than [`Name::MAX`] bytes keeps its first bytes and says so.

use core::fmt;

/// A short name, by value.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Name {
    bytes: [u8; Name::MAX],
    len: u8,
    cut: bool,
}

impl Name {
    /// Bytes kept.
    pub const MAX: usize = 48;

    pub fn new(s: &str) -> Name {
        let mut bytes = [0u8; Name::MAX];
        // Cut on a character boundary.
        let mut len = 0;
        for (i, ch) in s.char_indices() {
            let end = i + ch.len_utf8();
            if end > Name::MAX {
                break;
            }
            len = end;
        }
        bytes[..len].copy_from_slice(&s.as_bytes()[..len]);
        Name {
            bytes,
            len: len as u8,
            cut: len < s.len(),
        }
    }

    pub fn as_str(&self) -> &str {
        core::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or("")
    }
}

impl fmt::Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())?;
        if self.cut {
            f.write_str("...")?;
        }
        Ok(())
    }
}

impl fmt::Debug for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Name({self})")
    }
}

#[cfg(test)]
mod tests {
    use super::Name;

    #[test]
    fn a_long_name_keeps_its_start_and_says_it_was_cut() {
        assert_eq!(Name::new("abc").to_string(), "abc");
        let long = "x".repeat(200);
        let n = Name::new(&long);
        assert_eq!(n.as_str().len(), Name::MAX);
        assert!(n.to_string().ends_with("..."));
        let wide = "é".repeat(60);
        assert!(Name::new(&wide).as_str().chars().all(|c| c == 'é'));
    }
}
