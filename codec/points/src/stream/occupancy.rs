//! Version 3's child masks (`FORMAT.md` "Version 3"): version 2's bits and
//! contexts (with version 3's plane classes), each bit's probability mixed
//! (`probability.rs`) from three counters: the full context, the same
//! without the face bits (fewer, so it learns sooner), and version 1's
//! tree (the parent's child count and the exact bits so far). Where no
//! neighbour is occupied: the tree with the parent's child count, the tree
//! alone, and the child index with the bits set so far and the parent's
//! child count.

use vitrine_codec::entropy::{RangeDecoder, RangeEncoder};

use super::context::{Around, CODED_V3, CONTEXTS_V3};
use super::probability::{Counter, Mix, Mixer, INPUTS};

/// Parent classes (child count − 1) of the tree contexts.
const PARENT_CLASSES: usize = 8;
/// The contexts without their 8 face-bit combinations.
const SMALL: usize = CONTEXTS_V3 / 8;
/// Weight sets: one per small context without its near faces (child,
/// bits set, plane class), then one per child and bits set where no
/// neighbour is occupied.
const NEIGHBOUR_SETS: usize = SMALL / 4;
const LONE_SETS: usize = 8 * 3;

pub(crate) struct MaskCoder {
    context: Vec<Counter>,
    small: Vec<Counter>,
    tree: Vec<Counter>,
    sides: Vec<Counter>,
    lone_tree: Vec<Counter>,
    lone_node: Vec<Counter>,
    lone_child: Vec<Counter>,
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

/// Bits set so far: 0, 1, 2 or more.
fn set(so_far: u8) -> usize {
    (so_far.count_ones() as usize).min(2)
}

/// The counters of one bit (indices into the three tables of its kind)
/// and its weight set.
struct Slots {
    lone: bool,
    counters: [usize; INPUTS],
    set: usize,
}

impl MaskCoder {
    pub fn new() -> Self {
        MaskCoder {
            context: vec![Counter::default(); CONTEXTS_V3],
            small: vec![Counter::default(); SMALL],
            tree: vec![Counter::default(); PARENT_CLASSES * 256],
            sides: vec![Counter::default(); CONTEXTS_V3 / 4 * 8],
            lone_tree: vec![Counter::default(); PARENT_CLASSES * 256],
            lone_node: vec![Counter::default(); 256],
            lone_child: vec![Counter::default(); LONE_SETS * PARENT_CLASSES],
            mixer: Mixer::new(NEIGHBOUR_SETS + LONE_SETS),
        }
    }

    /// Child k's bit when the bits below it are `so_far`; `contexts` are
    /// `around.contexts_v3()`.
    fn slots(around: &Around, contexts: &[u16; 8], k: usize, class: u8, so_far: u8) -> Slots {
        let class = usize::from(class & 7);
        // A binary-tree node: the bits so far under a leading 1.
        let node = 1 << k | usize::from(so_far);
        if around.is_empty() {
            let child = k * 3 + set(so_far);
            Slots {
                lone: true,
                counters: [class * 256 + node, node, child * PARENT_CLASSES + class, 0],
                set: NEIGHBOUR_SETS + child,
            }
        } else {
            // (((k · 3 + set) · planes + plane) · 8 + face) · 4 + near.
            let context = usize::from(contexts[k] + CODED_V3[k][usize::from(so_far)]);
            Slots {
                lone: false,
                counters: [
                    context,
                    context / 32 * 4 + context % 4,
                    class * 256 + node,
                    context / 4 * 8 + near_sides(around.faces, k),
                ],
                set: context / 32,
            }
        }
    }

    fn predict(&self, s: &Slots) -> Mix {
        let [a, b, c, d] = s.counters;
        let inputs = if s.lone {
            [
                self.lone_tree[a],
                self.lone_node[b],
                self.lone_child[c],
                Counter::default(),
            ]
        } else {
            [self.context[a], self.small[b], self.tree[c], self.sides[d]]
        };
        self.mixer.predict(s.set, inputs)
    }

    fn learn(&mut self, s: &Slots, mix: &Mix, bit: bool) {
        self.mixer.learn(mix, bit);
        let [a, b, c, d] = s.counters;
        if s.lone {
            self.lone_tree[a].update(bit);
            self.lone_node[b].update(bit);
            self.lone_child[c].update(bit);
        } else {
            self.context[a].update(bit);
            self.small[b].update(bit);
            self.tree[c].update(bit);
            self.sides[d].update(bit);
        }
    }

    /// Codes a non-empty child mask; `class` is the parent's child count − 1.
    pub fn encode(&mut self, enc: &mut RangeEncoder, around: &Around, class: u8, mask: u8) {
        debug_assert!(mask != 0);
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
        let contexts = around.contexts_v3();
        let mut mask = 0u8;
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
