//! The adaptive models of the point stream and the coding steps that
//! encoder and decoder share, so that both use them in the same order.

use vitrine_codec::entropy::{BitModel, IntModel, RangeDecoder, RangeEncoder};

use super::attr::{colour_apply, colour_residual};
use super::context::{Around, CODED, CONTEXTS};
use super::occupancy::MaskCoder;
use super::predict::{Prediction, CLASSES};

/// Occupancy contexts: the parent's child count (1..=8) minus one.
const PARENT_CLASSES: usize = 8;

/// A point's coded attributes (only the ones the stream has are used).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Attr {
    pub normal: [u16; 2],
    pub colour: [u8; 3],
}

/// What the root's representative is predicted from.
pub(crate) fn root_prediction(normal_bits: u8) -> Attr {
    let mid = if normal_bits == 0 {
        0
    } else {
        1u16 << (normal_bits - 1)
    };
    Attr {
        normal: [mid, mid],
        colour: [128; 3],
    }
}

pub(crate) struct Models {
    /// `PARENT_CLASSES` trees of 256 nodes: the mask's bits, lowest child
    /// first, each conditioned on the bits before it.
    occupancy: Vec<BitModel>,
    /// Version 2: one model per neighbour context (`context.rs`).
    neighbour_occupancy: Vec<BitModel>,
    /// Version 3: version 2's contexts, mixed.
    pub masks_v3: MaskCoder,
    duplicates: IntModel,
    normal: [IntModel; 2],
    colour: [IntModel; 3],
    /// Predicted attributes (flag bit 2): residual models per class.
    predicted_normal: Vec<[IntModel; 2]>,
    predicted_colour: Vec<[IntModel; 3]>,
    has_normals: bool,
    has_colours: bool,
}

impl Models {
    pub fn new(has_normals: bool, has_colours: bool) -> Self {
        Models {
            occupancy: vec![BitModel::new(); PARENT_CLASSES * 256],
            neighbour_occupancy: vec![BitModel::new(); CONTEXTS],
            masks_v3: MaskCoder::new(),
            duplicates: IntModel::new(),
            normal: [IntModel::new(), IntModel::new()],
            colour: [IntModel::new(), IntModel::new(), IntModel::new()],
            predicted_normal: vec![[IntModel::new(), IntModel::new()]; CLASSES],
            predicted_colour: vec![[IntModel::new(), IntModel::new(), IntModel::new()]; CLASSES],
            has_normals,
            has_colours,
        }
    }

    /// Codes a non-empty child mask; `class` is the parent's child count − 1.
    pub fn encode_mask(&mut self, enc: &mut RangeEncoder, class: u8, mask: u8) {
        debug_assert!(mask != 0);
        let tree = &mut self.occupancy[usize::from(class) * 256..][..256];
        let mut node = 1usize;
        for k in 0..8 {
            // The last bit of a mask that is still empty must be set.
            if k == 7 && mask & 0x7F == 0 {
                break;
            }
            let bit = (mask >> k) & 1 == 1;
            enc.encode_bit(&mut tree[node], bit);
            node = node * 2 + usize::from(bit);
        }
    }

    /// Decodes a mask coded by [`encode_mask`](Self::encode_mask); never 0.
    pub fn decode_mask(&mut self, dec: &mut RangeDecoder<'_>, class: u8) -> u8 {
        let tree = &mut self.occupancy[usize::from(class & 7) * 256..][..256];
        let mut node = 1usize;
        let mut mask = 0u8;
        for k in 0..8 {
            if k == 7 && mask == 0 {
                return 0x80;
            }
            let bit = dec.decode_bit(&mut tree[node]);
            mask |= u8::from(bit) << k;
            node = node * 2 + usize::from(bit);
        }
        mask
    }

    /// Version 2: codes a non-empty child mask, each bit with the model of
    /// its neighbour context.
    pub fn encode_mask_v2(&mut self, enc: &mut RangeEncoder, around: &Around, class: u8, mask: u8) {
        debug_assert!(mask != 0);
        if around.is_empty() {
            return self.encode_mask(enc, class, mask);
        }
        let contexts = around.contexts();
        for k in 0..8 {
            let so_far = mask & ((1u8 << k) - 1);
            if k == 7 && so_far == 0 {
                break;
            }
            let context = contexts[k] + CODED[k][usize::from(so_far)];
            let model = &mut self.neighbour_occupancy[usize::from(context)];
            enc.encode_bit(model, (mask >> k) & 1 == 1);
        }
    }

    /// Decodes a mask coded by [`encode_mask_v2`](Self::encode_mask_v2);
    /// never 0.
    pub fn decode_mask_v2(&mut self, dec: &mut RangeDecoder<'_>, around: &Around, class: u8) -> u8 {
        if around.is_empty() {
            return self.decode_mask(dec, class);
        }
        let contexts = around.contexts();
        let mut mask = 0u8;
        for k in 0..8 {
            if k == 7 && mask == 0 {
                return 0x80;
            }
            let context = contexts[k] + CODED[k][usize::from(mask)];
            let model = &mut self.neighbour_occupancy[usize::from(context)];
            mask |= u8::from(dec.decode_bit(model)) << k;
        }
        mask
    }

    pub fn encode_duplicates(&mut self, enc: &mut RangeEncoder, extra: u32) {
        enc.encode_uint(&mut self.duplicates, extra);
    }

    pub fn decode_duplicates(&mut self, dec: &mut RangeDecoder<'_>) -> u32 {
        dec.decode_uint(&mut self.duplicates)
    }

    pub fn encode_attr(&mut self, enc: &mut RangeEncoder, a: Attr, pred: Attr) {
        if self.has_normals {
            for k in 0..2 {
                let d = i32::from(a.normal[k]) - i32::from(pred.normal[k]);
                enc.encode_int(&mut self.normal[k], d);
            }
        }
        if self.has_colours {
            let r = colour_residual(a.colour, pred.colour);
            for (k, model) in self.colour.iter_mut().enumerate() {
                enc.encode_int(model, r[k]);
            }
        }
    }

    /// `None` when the decoded residuals leave the value range (corrupt).
    pub fn decode_attr(
        &mut self,
        dec: &mut RangeDecoder<'_>,
        pred: Attr,
        normal_max: u16,
    ) -> Option<Attr> {
        let mut a = Attr::default();
        if self.has_normals {
            for k in 0..2 {
                let d = dec.decode_int(&mut self.normal[k]);
                let v = i32::from(pred.normal[k]).checked_add(d)?;
                a.normal[k] = u16::try_from(v).ok().filter(|&v| v <= normal_max)?;
            }
        }
        if self.has_colours {
            let r = [0, 1, 2].map(|k| dec.decode_int(&mut self.colour[k]));
            a.colour = colour_apply(r, pred.colour)?;
        }
        Some(a)
    }

    /// Codes a new point's attributes against a neighbourhood prediction
    /// (flag bit 2), with the models of the prediction's classes.
    pub fn encode_predicted(&mut self, enc: &mut RangeEncoder, a: Attr, p: &Prediction) {
        if self.has_normals {
            let models = &mut self.predicted_normal[usize::from(p.normal_class)];
            for (k, model) in models.iter_mut().enumerate() {
                let d = i32::from(a.normal[k]) - i32::from(p.attr.normal[k]);
                enc.encode_int(model, d);
            }
        }
        if self.has_colours {
            let r = colour_residual(a.colour, p.attr.colour);
            let models = &mut self.predicted_colour[usize::from(p.colour_class)];
            for (k, model) in models.iter_mut().enumerate() {
                enc.encode_int(model, r[k]);
            }
        }
    }

    /// Decodes what [`encode_predicted`](Self::encode_predicted) coded;
    /// `None` when a value leaves its range (corrupt).
    pub fn decode_predicted(
        &mut self,
        dec: &mut RangeDecoder<'_>,
        p: &Prediction,
        normal_max: u16,
    ) -> Option<Attr> {
        let mut a = Attr::default();
        if self.has_normals {
            let models = &mut self.predicted_normal[usize::from(p.normal_class) % CLASSES];
            for (k, model) in models.iter_mut().enumerate() {
                let d = dec.decode_int(model);
                let v = i32::from(p.attr.normal[k]).checked_add(d)?;
                a.normal[k] = u16::try_from(v).ok().filter(|&v| v <= normal_max)?;
            }
        }
        if self.has_colours {
            let models = &mut self.predicted_colour[usize::from(p.colour_class) % CLASSES];
            let r = [0, 1, 2].map(|k| dec.decode_int(&mut models[k]));
            a.colour = colour_apply(r, p.attr.colour)?;
        }
        Some(a)
    }
}
