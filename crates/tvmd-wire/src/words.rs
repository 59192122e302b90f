//! Cursors over little-endian `u32` words holding `f32` bits.

use tvmd_core::nalgebra::{Matrix3, Vector3, Vector6};

/// A cursor writing words into a buffer; every method returns `None` when it is full.
pub struct Writer<'a> {
    buf: &'a mut [u32],
    at: usize,
}

impl<'a> Writer<'a> {
    /// Writes from the start of `buf`.
    pub fn new(buf: &'a mut [u32]) -> Self {
        Self { buf, at: 0 }
    }

    /// Words written.
    pub fn len(&self) -> usize {
        self.at
    }

    /// Nothing written yet.
    pub fn is_empty(&self) -> bool {
        self.at == 0
    }

    /// One word.
    pub fn u32(&mut self, w: u32) -> Option<()> {
        *self.buf.get_mut(self.at)? = w;
        self.at += 1;
        Some(())
    }

    /// One float's bits.
    pub fn f32(&mut self, x: f32) -> Option<()> {
        self.u32(x.to_bits())
    }

    /// Floats.
    pub fn f32s(&mut self, xs: &[f32]) -> Option<()> {
        xs.iter().try_for_each(|x| self.f32(*x))
    }

    /// A matrix, row by row.
    pub fn m3(&mut self, m: &Matrix3<f32>) -> Option<()> {
        (0..3).try_for_each(|i| (0..3).try_for_each(|j| self.f32(*m.get((i, j))?)))
    }
}

/// A cursor reading words; every method returns `None` past the end.
pub struct Reader<'a> {
    words: &'a [u32],
    at: usize,
}

impl<'a> Reader<'a> {
    /// Reads from the start of `words`.
    pub fn new(words: &'a [u32]) -> Self {
        Self { words, at: 0 }
    }

    /// Words not read yet.
    pub fn remaining(&self) -> usize {
        self.words.len().saturating_sub(self.at)
    }

    /// One word.
    pub fn u32(&mut self) -> Option<u32> {
        let w = *self.words.get(self.at)?;
        self.at += 1;
        Some(w)
    }

    /// One float.
    pub fn f32(&mut self) -> Option<f32> {
        self.u32().map(f32::from_bits)
    }

    /// `K` floats.
    pub fn array<const K: usize>(&mut self) -> Option<[f32; K]> {
        let mut a = [0.0; K];
        for x in &mut a {
            *x = self.f32()?;
        }
        Some(a)
    }

    /// A vector.
    pub fn v3(&mut self) -> Option<Vector3<f32>> {
        self.array::<3>().map(Vector3::from)
    }

    /// A six-vector.
    pub fn v6(&mut self) -> Option<Vector6<f32>> {
        self.array::<6>().map(Vector6::from)
    }

    /// A matrix, row by row.
    pub fn m3(&mut self) -> Option<Matrix3<f32>> {
        let r = self.array::<9>()?;
        Some(Matrix3::new(
            r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8],
        ))
    }
}
