//! The names of the parameter enums ([`crate::Algorithm`], [`crate::DeadEnd`],
//! [`crate::SmoothingKind`]): one table per enum gives `ALL`, `name`, `from_name` and `Display`,
//! so the lower-case names (the same as their serde names) are written once.

/// `impl` `ALL` (in the table's order), `name`, `from_name` (case-insensitive) and `Display` for
/// an enum, from its variants and their lower-case names: `named!(Enum, "doc of ALL", [A => "a"])`.
macro_rules! named {
    ($ty:ident, $all:literal, [$($v:ident => $n:literal),+ $(,)?]) => {
        impl $ty {
            #[doc = $all]
            pub const ALL: [$ty; [$($n),+].len()] = [$($ty::$v),+];

            /// Lower-case name (also the serde name).
            pub const fn name(self) -> &'static str {
                match self {
                    $($ty::$v => $n,)+
                }
            }

            /// Parse a name (case-insensitive).
            pub fn from_name(s: &str) -> Option<Self> {
                Self::ALL
                    .into_iter()
                    .find(|v| v.name().eq_ignore_ascii_case(s))
            }
        }

        impl core::fmt::Display for $ty {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

pub(crate) use named;
