//! The adaptive models of the point stream and the coding steps that
//! encoder and decoder share, so that both use them in the same order.

use vitrine_codec::entropy::{BitModel, IntModel, RangeDecoder, RangeEncoder};

use super::attr::{colour_apply, colour_residual, Attr};
use super::context::{Around, CODED, CONTEXTS};
use super::occupancy::MaskCoder;
use super::predict::{Prediction, CLASSES};

/// Occupancy contexts: the parent's child count (1..=8) minus one.
const PARENT_CLASSES: usize = 8;

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
    /// Predicted attributes (flag bit 2): residual models per class, the
    /// second normal component's and the red and blue ones' also by the
    /// size of the first residual (`linked`).
    predicted_u: Vec<IntModel>,
    predicted_v: Vec<IntModel>,
    predicted_green: Vec<IntModel>,
    predicted_red_blue: Vec<[IntModel; 2]>,
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
            predicted_u: vec![IntModel::new(); CLASSES],
            predicted_v: vec![IntModel::new(); CLASSES * LINKED],
            predicted_green: vec![IntModel::new(); CLASSES],
            predicted_red_blue: vec![[IntModel::new(), IntModel::new()]; CLASSES * LINKED],
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
            let class = usize::from(p.normal_class);
            let d = [0, 1].map(|k| i32::from(a.normal[k]) - i32::from(p.attr.normal[k]));
            enc.encode_int(&mut self.predicted_u[class], d[0]);
            enc.encode_int(&mut self.predicted_v[class * LINKED + linked(d[0])], d[1]);
        }
        if self.has_colours {
            let class = usize::from(p.colour_class);
            let r = colour_residual(a.colour, p.attr.colour);
            enc.encode_int(&mut self.predicted_green[class], r[0]);
            let models = &mut self.predicted_red_blue[class * LINKED + linked(r[0])];
            enc.encode_int(&mut models[0], r[1]);
            enc.encode_int(&mut models[1], r[2]);
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
            let class = usize::from(p.normal_class) % CLASSES;
            let du = dec.decode_int(&mut self.predicted_u[class]);
            let dv = dec.decode_int(&mut self.predicted_v[class * LINKED + linked(du)]);
            for (k, d) in [du, dv].into_iter().enumerate() {
                let v = i32::from(p.attr.normal[k]).checked_add(d)?;
                a.normal[k] = u16::try_from(v).ok().filter(|&v| v <= normal_max)?;
            }
        }
        if self.has_colours {
            let class = usize::from(p.colour_class) % CLASSES;
            let g = dec.decode_int(&mut self.predicted_green[class]);
            let models = &mut self.predicted_red_blue[class * LINKED + linked(g)];
            let r = [
                g,
                dec.decode_int(&mut models[0]),
                dec.decode_int(&mut models[1]),
            ];
            a.colour = colour_apply(r, p.attr.colour)?;
        }
        Some(a)
    }
}

/// Bins of the first residual's size that pick the next residuals' models.
const LINKED: usize = 8;

/// The bin of a residual: its magnitude's bit length, at most `LINKED − 1`.
fn linked(d: i32) -> usize {
    let bits = 32 - d.unsigned_abs().leading_zeros();
    (bits as usize).min(LINKED - 1)
}
