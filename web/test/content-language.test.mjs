// @ts-check
// A model's title, description and credit in the visitor's language
// (content-language.js): preferences in order, exact tags before primary
// languages, each field on its own, the default text and its language last.
import assert from 'node:assert/strict';
import test from 'node:test';
import { chooseText, chooseTexts, markLanguage } from '../src/content-language.js';

const MANIFEST = {
  title: 'Funerary mask',
  description: 'Gilded cartonnage, Late Period.',
  rights: { credit: 'Scan: Test Museum', licence: null },
  language: 'en',
  translations: {
    pt: { title: 'Máscara funerária', description: 'Cartonagem dourada, Época Baixa.', credit: 'Digitalização: Museu de Teste' },
    'es-MX': { title: 'Máscara funeraria' },
    'fr-CA': { title: 'Masque funéraire (Canada)' },
    fr: { title: 'Masque funéraire' },
  },
};

test('a translation in the first preference wins; the default text, with its language, when none matches', () => {
  assert.deepEqual(chooseText(MANIFEST, 'title', ['pt']), { text: 'Máscara funerária', lang: 'pt' });
  assert.deepEqual(chooseText(MANIFEST, 'credit', ['pt']), { text: 'Digitalização: Museu de Teste', lang: 'pt' });
  assert.deepEqual(chooseText(MANIFEST, 'title', ['de']), { text: 'Funerary mask', lang: 'en' });
  assert.deepEqual(chooseText(MANIFEST, 'title', []), { text: 'Funerary mask', lang: 'en' });
  assert.deepEqual(chooseText(MANIFEST, 'title', ['de', 'pt']), { text: 'Máscara funerária', lang: 'pt' }, 'the browser’s second language');
});

test('the default language counts as a preference like any other', () => {
  assert.deepEqual(chooseText(MANIFEST, 'title', ['en-GB', 'pt']), { text: 'Funerary mask', lang: 'en' });
});

test('tags match case aside, or by their primary language, the exact one first', () => {
  assert.deepEqual(chooseText(MANIFEST, 'title', ['PT-br']), { text: 'Máscara funerária', lang: 'pt' });
  assert.deepEqual(chooseText(MANIFEST, 'title', ['es']), { text: 'Máscara funeraria', lang: 'es-MX' });
  assert.deepEqual(chooseText(MANIFEST, 'title', ['fr']), { text: 'Masque funéraire', lang: 'fr' });
  assert.deepEqual(chooseText(MANIFEST, 'title', ['fr-ca']), { text: 'Masque funéraire (Canada)', lang: 'fr-CA' });
  assert.deepEqual(chooseText(MANIFEST, 'title', ['fr_CA']), { text: 'Masque funéraire (Canada)', lang: 'fr-CA' });
});

test('a field a translation leaves out comes from further down the preferences, then the default', () => {
  assert.deepEqual(chooseText(MANIFEST, 'description', ['es']), { text: 'Gilded cartonnage, Late Period.', lang: 'en' });
  assert.deepEqual(chooseText(MANIFEST, 'description', ['es', 'pt']), { text: 'Cartonagem dourada, Época Baixa.', lang: 'pt' });
  const texts = chooseTexts(MANIFEST, ['es']);
  assert.deepEqual(texts.title, { text: 'Máscara funeraria', lang: 'es-MX' });
  assert.deepEqual(texts.credit, { text: 'Scan: Test Museum', lang: 'en' });
});

test('no stated language: the default text with lang null; blank translations are none', () => {
  const unstated = { title: 'Torus', description: '', rights: null, language: null, translations: { it: { title: '  ' } } };
  assert.deepEqual(chooseText(unstated, 'title', ['it']), { text: 'Torus', lang: null });
  assert.deepEqual(chooseText(unstated, 'credit', ['it']), { text: '', lang: null });
  assert.deepEqual(chooseText({ title: 'Old server' }, 'title', ['pt']), { text: 'Old server', lang: null }, 'no language fields at all');
  assert.deepEqual(chooseText(null, 'title', ['pt']), { text: '', lang: null });
});

test('a gallery entry (titles only) picks its title the same way', () => {
  const entry = { title: 'Vase', language: 'it', translations: { ar: { title: 'مزهرية' } } };
  assert.deepEqual(chooseText(entry, 'title', ['ar']), { text: 'مزهرية', lang: 'ar' });
  assert.deepEqual(chooseText(entry, 'title', ['it-CH']), { text: 'Vase', lang: 'it' });
});

test('an element carries lang when it is known, and dir="auto" in another language than the page’s', () => {
  /** @type {Map<string, string>} */
  const attributes = new Map();
  const element = /** @type {Element} */ (
    /** @type {unknown} */ ({
      setAttribute: (/** @type {string} */ k, /** @type {string} */ v) => attributes.set(k, v),
      removeAttribute: (/** @type {string} */ k) => attributes.delete(k),
    })
  );
  markLanguage(element, 'pt', 'pt');
  assert.deepEqual(Object.fromEntries(attributes), { lang: 'pt' });
  markLanguage(element, 'pt-BR', 'pt');
  assert.deepEqual(Object.fromEntries(attributes), { lang: 'pt-BR' });
  markLanguage(element, 'ar', 'en');
  assert.deepEqual(Object.fromEntries(attributes), { lang: 'ar', dir: 'auto' });
  markLanguage(element, null, 'en');
  assert.deepEqual(Object.fromEntries(attributes), {});
});
