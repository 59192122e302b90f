//! [`Stored`]: an optional value with a defined layout, for the state a controller keeps. A
//! controller in memory a stray write may have changed (a C caller's handle) is checked raw
//! before any reference to it is made ([`crate::Controller::storage_intact`]); `Option<T>`'s
//! tag has no defined place or values, so an invalid one could not even be found, and reading
//! it would be undefined behaviour. `Stored` is `repr(u8)` (RFC 2195): its tag is the first
//! byte, 0 absent and 1 present, and the value follows at `align_of::<T>()`.
//!
//! Also here: the raw checks of a stored `bool` and of a `repr(u8)` enum's tag.

use core::mem::align_of;

/// An optional value with a defined layout: `Option<T>` as a controller stores it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(u8)]
pub enum Stored<T> {
    /// No value (tag 0).
    #[default]
    Absent,
    /// A value (tag 1).
    Present(T),
}

impl<T> Stored<T> {
    /// The value, by reference.
    #[inline]
    pub const fn as_ref(&self) -> Option<&T> {
        match self {
            Self::Absent => None,
            Self::Present(v) => Some(v),
        }
    }

    /// The value, by mutable reference.
    #[inline]
    pub fn as_mut(&mut self) -> Option<&mut T> {
        match self {
            Self::Absent => None,
            Self::Present(v) => Some(v),
        }
    }

    /// Whether there is a value.
    #[inline]
    pub const fn is_some(&self) -> bool {
        matches!(self, Self::Present(_))
    }

    /// Whether there is none.
    #[inline]
    pub const fn is_none(&self) -> bool {
        !self.is_some()
    }

    /// The value as an `Option`.
    #[inline]
    pub fn get(self) -> Option<T> {
        match self {
            Self::Absent => None,
            Self::Present(v) => Some(v),
        }
    }

    /// Takes the value out, leaving [`Self::Absent`].
    #[inline]
    pub fn take(&mut self) -> Option<T> {
        core::mem::take(self).get()
    }

    /// Whether the `Stored` at `this` has a valid tag and, when present, `value` accepts the
    /// value's address (for a value that holds tags of its own; floats need no check).
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` readable bytes; `value` is called
    /// only with the in-bounds, aligned address of the value.
    #[inline]
    pub unsafe fn storage_intact(this: *const Self, value: impl FnOnce(*const T) -> bool) -> bool {
        match this.cast::<u8>().read() {
            0 => true,
            // `repr(u8)`: the variant is a `repr(C)` struct of the tag and the value, which
            // starts at the tag's size rounded up to its alignment.
            1 => value(this.cast::<u8>().add(align_of::<T>()).cast::<T>()),
            _ => false,
        }
    }

    /// Writes `value` at `this` as a `Stored`: the tag, and the value (if any) in place where
    /// [`Self::storage_intact`] finds it, with no `Stored` built on the stack first.
    ///
    /// # Safety
    /// `this` is aligned and points to `size_of::<Self>()` writable bytes.
    #[inline(always)]
    pub unsafe fn write_from(this: *mut Self, value: &Option<T>)
    where
        T: Copy,
    {
        match value {
            None => this.write(Self::Absent),
            Some(v) => {
                this.cast::<u8>().write(1);
                this.cast::<u8>().add(align_of::<T>()).cast::<T>().write(*v);
            }
        }
    }

    /// [`Self::storage_intact`] of a value of plain numbers (every bit pattern a value).
    ///
    /// # Safety
    /// As [`Self::storage_intact`].
    #[inline]
    pub unsafe fn tag_intact(this: *const Self) -> bool {
        this.cast::<u8>().read() <= 1
    }
}

impl<'a, T> IntoIterator for &'a Stored<T> {
    type Item = &'a T;
    type IntoIter = core::option::IntoIter<&'a T>;

    /// The value, if any (as `&Option<T>` iterates).
    #[inline]
    fn into_iter(self) -> Self::IntoIter {
        self.as_ref().into_iter()
    }
}

impl<T> From<Option<T>> for Stored<T> {
    #[inline]
    fn from(value: Option<T>) -> Self {
        match value {
            None => Self::Absent,
            Some(v) => Self::Present(v),
        }
    }
}

impl<T> From<Stored<T>> for Option<T> {
    #[inline]
    fn from(value: Stored<T>) -> Self {
        value.get()
    }
}

/// Whether the `bool` at `p` holds 0 or 1 (read as a byte).
///
/// # Safety
/// `p` is aligned and points to one readable byte.
#[inline]
pub unsafe fn bool_intact(p: *const bool) -> bool {
    p.cast::<u8>().read() <= 1
}

/// Whether the `repr(u8)` enum at `p` has one of its `variants` tags (`0..variants`).
///
/// # Safety
/// `p` points to a readable, initialized byte (the enum's tag, first in a `repr(u8)` enum).
#[inline]
pub unsafe fn tag_below<E>(p: *const E, variants: u8) -> bool {
    p.cast::<u8>().read() < variants
}

/// Whether `check` refuses a copy of `value` with `byte` written at `at` (a byte of the copy);
/// for the tests of each type's `storage_intact`. The copy is never used as a value again.
#[cfg(test)]
pub(crate) fn refuses<S: Copy>(
    value: &S,
    byte: u8,
    at: impl FnOnce(*mut S) -> *mut u8,
    check: unsafe fn(*const S) -> bool,
) -> bool {
    let mut copy = core::mem::MaybeUninit::new(*value);
    let p = copy.as_mut_ptr();
    // SAFETY: `at` gives a byte inside the copy; `check` reads it raw.
    unsafe {
        at(p).write(byte);
        !check(p)
    }
}

/// Whether `check` accepts `value` as it is.
#[cfg(test)]
pub(crate) fn accepts<S>(value: &S, check: unsafe fn(*const S) -> bool) -> bool {
    // SAFETY: a valid value.
    unsafe { check(value) }
}

/// How many bytes of `value` `check` refuses when `byte` is written there, one at a time: the
/// tags it checks, for the tests of a type's `storage_intact` that count them.
#[cfg(test)]
pub(crate) fn refused_bytes<S: Copy>(
    value: &S,
    byte: u8,
    check: unsafe fn(*const S) -> bool,
) -> usize {
    (0..core::mem::size_of::<S>())
        .filter(|&k| refuses(value, byte, |p| unsafe { p.cast::<u8>().add(k) }, check))
        .count()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use core::ptr::addr_of_mut;
    use nalgebra::Vector3;

    #[test]
    fn the_value_is_where_the_check_reads_it() {
        fn at<T>(s: &Stored<T>) -> *const T {
            let mut seen = core::ptr::null();
            // SAFETY: a valid `Stored`.
            assert!(unsafe {
                Stored::storage_intact(s, |p| {
                    seen = p;
                    true
                })
            });
            seen
        }
        let a = Stored::Present(3_u16);
        assert_eq!(at(&a), a.as_ref().unwrap() as *const u16);
        let b = Stored::Present((7_u8, Vector3::new(1.0_f32, 2.0, 3.0)));
        assert_eq!(at(&b), b.as_ref().unwrap() as *const _);
        let c = Stored::Present(Vector3::new(1.0_f64, 2.0, 3.0));
        assert_eq!(at(&c), c.as_ref().unwrap() as *const _);
        assert!(unsafe { Stored::<f64>::tag_intact(&Stored::Absent) });
    }

    #[test]
    fn a_tag_past_present_is_refused() {
        let mut s = Stored::Present(1.5_f32);
        let p: *mut Stored<f32> = &mut s;
        unsafe {
            assert!(Stored::tag_intact(p));
            p.cast::<u8>().write(2);
            assert!(!Stored::tag_intact(p));
            assert!(!Stored::storage_intact(p, |_| true));
            let mut b = true;
            let q: *mut bool = addr_of_mut!(b);
            assert!(bool_intact(q));
            q.cast::<u8>().write(2);
            assert!(!bool_intact(q));
        }
        let mut o: Stored<u8> = Some(4).into();
        assert_eq!(o.take(), Some(4));
        assert!(!o.is_some() && Option::<u8>::from(o).is_none());
    }
}
