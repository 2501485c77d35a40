//! Serde glue: [`Point`] as it goes on the wire (a remote derive, the grid stays free of serde)
//! and the packed waypoint list. The parameters need none: [`crate::Params`] and its enums derive
//! serde themselves (feature `serde`), so a new parameter is sent without a line here.

use core::fmt;

use serde::de::{Deserializer, Error as _};
use serde::ser::{SerializeSeq, Serializer};
use serde::{Deserialize, Serialize};

use crate::map::grid::Point;

/// [`Point`]: `x`, `y` as varints.
#[derive(Serialize, Deserialize)]
#[serde(remote = "Point")]
pub(crate) struct PointDef {
    x: u16,
    y: u16,
}

/// Bytes per waypoint on the wire: `x` then `y`, each a little-endian `u16`.
pub const WAYPOINT_BYTES: usize = 4;

/// The waypoints of a [`super::PathReply`]: on the wire one byte string of 4 bytes a point
/// (`x` u16 LE, `y` u16 LE), so both ends handle it without copying or allocating. The sender
/// builds it from a slice of points, the receiver gets the packed bytes; [`Waypoints::iter`]
/// reads either.
#[derive(Clone, Copy)]
pub enum Waypoints<'a> {
    /// Points to send.
    Points(&'a [Point]),
    /// Points as received (length a multiple of [`WAYPOINT_BYTES`]).
    Packed(&'a [u8]),
}

impl<'a> Waypoints<'a> {
    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            Waypoints::Points(p) => p.len(),
            Waypoints::Packed(b) => b.len() / WAYPOINT_BYTES,
        }
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `i`-th point.
    pub fn get(&self, i: usize) -> Option<Point> {
        match self {
            Waypoints::Points(p) => p.get(i).copied(),
            Waypoints::Packed(b) => {
                let at = i.checked_mul(WAYPOINT_BYTES)?;
                match b.get(at..at.checked_add(WAYPOINT_BYTES)?)? {
                    &[x0, x1, y0, y1] => Some(Point::new(
                        u16::from_le_bytes([x0, x1]),
                        u16::from_le_bytes([y0, y1]),
                    )),
                    _ => None,
                }
            }
        }
    }

    /// The points, first to last.
    pub fn iter(&self) -> impl Iterator<Item = Point> + 'a {
        let w = *self;
        (0..w.len()).filter_map(move |i| w.get(i))
    }
}

impl fmt::Debug for Waypoints<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl PartialEq for Waypoints<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().eq(other.iter())
    }
}

impl Serialize for Waypoints<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        // A sequence of `u8` is exactly how postcard writes a byte string (varint length, then
        // the bytes), so the receiver can borrow it as `&[u8]` without a packed copy here.
        let n = self.len().saturating_mul(WAYPOINT_BYTES);
        let mut seq = s.serialize_seq(Some(n))?;
        for p in self.iter() {
            for b in p.x.to_le_bytes().into_iter().chain(p.y.to_le_bytes()) {
                seq.serialize_element(&b)?;
            }
        }
        seq.end()
    }
}

impl<'de: 'a, 'a> Deserialize<'de> for Waypoints<'a> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let b = <&'de [u8]>::deserialize(d)?;
        if b.len() % WAYPOINT_BYTES != 0 {
            return Err(D::Error::invalid_length(b.len(), &"a multiple of 4 bytes"));
        }
        Ok(Waypoints::Packed(b))
    }
}
