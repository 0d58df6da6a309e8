//! Version 3's child masks (`FORMAT.md` "Version 3"): version 2's bits and
//! contexts (with version 3's plane classes), each bit's probability mixed
//! (`probability.rs`) from three counters: the full context, version 1's
//! tree (the parent's child count and the exact bits so far), and the
//! full context with the child's occupied near faces as bits, not a count.
//! (A fourth, the context without its face bits, saved 0.07 %.)
//! Where no neighbour is occupied (most cells of the deepest depths, whose
//! bits no context predicts much), version 1's tree alone, with an
//! adaptive-rate counter: mixing there saved 0.05 % for a third of the
//! bits' time.

use vitrine_codec::entropy::{RangeDecoder, RangeEncoder};

use super::context::{Around, CODED_V3, CONTEXTS_V3};
use super::probability::{Counters, Mix, Mixer, INPUTS, SETS};

/// Parent classes (child count − 1) of the tree contexts.
const PARENT_CLASSES: usize = 8;
/// Weight sets: one per child, bits set and plane class (the context
/// without its face bits and near faces).
const _: () = assert!(CONTEXTS_V3 / 32 <= SETS);
/// Counter tables, powers of two at least the contexts (`Counters`).
const CONTEXT_SLOTS: usize = 8192;
const SIDES_SLOTS: usize = 16384;
const _: () = assert!(CONTEXTS_V3 <= CONTEXT_SLOTS && CONTEXTS_V3 / 4 * 8 <= SIDES_SLOTS);
const TREE_SLOTS: usize = PARENT_CLASSES * 256;

pub(crate) struct MaskCoder {
    context: Counters<CONTEXT_SLOTS>,
    tree: Counters<TREE_SLOTS>,
    sides: Counters<SIDES_SLOTS>,
    /// Where no neighbour is occupied: version 1's tree, one counter alone.
    lone_tree: Counters<TREE_SLOTS>,
    mixer: Mixer,
}

/// Which of child k's sides (bit a: axis a) have their face neighbour
/// occupied (`Around::faces`).
fn near_sides(faces: u8, k: usize) -> usize {
    let mut sides = 0;
    for a in 0..3 {
        sides |= usize::from(faces >> (2 * a + (k >> a & 1)) & 1) << a;
    }
    sides
}

/// The counters of one bit and its weight set.
struct Slots {
    counters: [usize; INPUTS],
    set: usize,
}

impl MaskCoder {
    pub fn new() -> Self {
        MaskCoder {
            context: Counters::new(),
            tree: Counters::new(),
            sides: Counters::new(),
            lone_tree: Counters::new(),
            mixer: Mixer::new(),
        }
    }

    /// Child k's bit when the bits below it are `so_far`; `contexts` are
    /// `around.contexts_v3()`.
    fn slots(around: &Around, contexts: &[u16; 8], k: usize, class: u8, so_far: u8) -> Slots {
        let class = usize::from(class & 7);
        // A binary-tree node: the bits so far under a leading 1.
        let node = 1 << k | usize::from(so_far);
        // (((k · 3 + set) · planes + plane) · 8 + face) · 4 + near.
        let context = usize::from(contexts[k] + CODED_V3[k][usize::from(so_far)]);
        Slots {
            counters: [
                context,
                class * 256 + node,
                context / 4 * 8 + near_sides(around.faces, k),
            ],
            set: context / 32,
        }
    }

    fn predict(&self, s: &Slots) -> Mix {
        let [a, c, d] = s.counters;
        let inputs = [self.context.get(a), self.tree.get(c), self.sides.get(d)];
        self.mixer.predict(s.set, inputs)
    }

    fn learn(&mut self, s: &Slots, mix: &Mix, bit: bool) {
        self.mixer.learn(mix, bit);
        let [a, c, d] = s.counters;
        self.context.at(a).update(bit);
        self.tree.at(c).update(bit);
        self.sides.at(d).update(bit);
    }

    /// Codes a non-empty child mask; `class` is the parent's child count − 1.
    pub fn encode(&mut self, enc: &mut RangeEncoder, around: &Around, class: u8, mask: u8) {
        debug_assert!(mask != 0);
        if around.is_empty() {
            let tree = usize::from(class & 7) * 256;
            for k in 0..8 {
                let so_far = mask & ((1u8 << k) - 1);
                if k == 7 && so_far == 0 {
                    break;
                }
                let node = tree + (1 << k | usize::from(so_far));
                self.lone_tree.at(node).encode(enc, (mask >> k) & 1 == 1);
            }
            return;
        }
        let contexts = around.contexts_v3();
        for k in 0..8 {
            let so_far = mask & ((1u8 << k) - 1);
            // The last bit of a mask that is still empty must be set.
            if k == 7 && so_far == 0 {
                break;
            }
            let slots = Self::slots(around, &contexts, k, class, so_far);
            let mix = self.predict(&slots);
            let bit = (mask >> k) & 1 == 1;
            mix.encode(enc, bit);
            self.learn(&slots, &mix, bit);
        }
    }

    /// Decodes a mask coded by [`encode`](Self::encode); never 0.
    pub fn decode(&mut self, dec: &mut RangeDecoder<'_>, around: &Around, class: u8) -> u8 {
        let mut mask = 0u8;
        if around.is_empty() {
            let tree = usize::from(class & 7) * 256;
            for k in 0..8 {
                if k == 7 && mask == 0 {
                    return 0x80;
                }
                let node = tree + (1 << k | usize::from(mask));
                mask |= u8::from(self.lone_tree.at(node).decode(dec)) << k;
            }
            return mask;
        }
        let contexts = around.contexts_v3();
        for k in 0..8 {
            if k == 7 && mask == 0 {
                return 0x80;
            }
            let slots = Self::slots(around, &contexts, k, class, mask);
            let mix = self.predict(&slots);
            let bit = mix.decode(dec);
            self.learn(&slots, &mix, bit);
            mask |= u8::from(bit) << k;
        }
        mask
    }
}
