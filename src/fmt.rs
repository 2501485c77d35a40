//! Logging macros that forward to `defmt` when the `defmt` feature is on and to nothing
//! otherwise (the embassy-sync pattern), so the core logs on the device and stays silent and
//! dependency-free on the host.
#![allow(unused_macros, unused_imports)]

macro_rules! trace {
    ($($x:tt)*) => {{
        #[cfg(feature = "defmt")]
        ::defmt::trace!($($x)*);
    }};
}

macro_rules! debug {
    ($($x:tt)*) => {{
        #[cfg(feature = "defmt")]
        ::defmt::debug!($($x)*);
    }};
}

pub(crate) use debug;
pub(crate) use trace;

macro_rules! warning {
    ($($x:tt)*) => {{
        #[cfg(feature = "defmt")]
        ::defmt::warn!($($x)*);
    }};
}

pub(crate) use warning;
