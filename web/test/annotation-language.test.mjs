// @ts-check
// Curators' notes in the visitor's language (annotations.js, note-editor.js):
// the served translations as the viewer keeps them, the language chosen for
// title and text together (the model texts' order of preference), and the
// editor's rows as the `translations` a curator's save sends.
import assert from 'node:assert/strict';
import test from 'node:test';
import { noteInLanguage, parseAnnotations } from '../src/annotations.js';
import { MAX_TRANSLATIONS, isLanguageTag, translationsOf } from '../src/note-editor.js';

const SERVED = {
  id: 7,
  title: 'Gilded rim',
  text: 'The *rim* was gilded.',
  html: '<p>The <em>rim</em> was gilded.</p>',
  position: [0, 1, 0],
  normal: [0, 1, 0],
  view: { target: [0, 0, 0], distance: 3, yaw: 0.5, pitch: 0.1 },
  language: 'en',
  translations: {
    pt: { title: 'Borda dourada', text: 'A *borda* foi dourada.', html: '<p>A <em>borda</em> foi dourada.</p>' },
    'es-MX': { title: 'Borde dorado', text: '', html: '' },
    fr: { title: '', text: 'Sans titre', html: '<p>Sans titre</p>' },
  },
};

const [NOTE] = parseAnnotations([SERVED]);

test('a served note keeps its language, its translations with a title, and its view as sent', () => {
  assert.equal(NOTE.language, 'en');
  assert.deepEqual(Object.keys(NOTE.translations), ['pt', 'es-MX']);
  assert.deepEqual(NOTE.translations['es-MX'], { title: 'Borde dorado', text: '', html: '' });
  assert.deepEqual(NOTE.savedView, SERVED.view);
  const [bare] = parseAnnotations([{ ...SERVED, language: null, translations: undefined }]);
  assert.equal(bare.language, null);
  assert.deepEqual(bare.translations, {});
  const [odd] = parseAnnotations([{ ...SERVED, language: '  ', translations: ['pt'] }]);
  assert.equal(odd.language, null);
  assert.deepEqual(odd.translations, {});
});

test('title and text come from the language chosen, with its tag; the own words when none matches', () => {
  assert.deepEqual(noteInLanguage(NOTE, ['pt']), { ...SERVED.translations.pt, lang: 'pt' });
  assert.deepEqual(noteInLanguage(NOTE, ['de']), { title: SERVED.title, text: SERVED.text, html: SERVED.html, lang: 'en' });
  assert.deepEqual(noteInLanguage(NOTE, ['de', 'pt-BR']).lang, 'pt', 'the browser’s second language, by its primary subtag');
  assert.deepEqual(noteInLanguage(NOTE, ['es']), { title: 'Borde dorado', text: '', html: '', lang: 'es-MX' });
  assert.deepEqual(noteInLanguage(NOTE, ['en-GB', 'pt']).lang, 'en', 'the note’s own language is a preference like any other');
  assert.equal(noteInLanguage(NOTE, ['fr']).lang, 'en', 'a translation without a title is not offered');
  assert.equal(noteInLanguage(NOTE, []).title, 'Gilded rim');
});

test('a note of no stated language is shown as it is where no translation matches', () => {
  const [note] = parseAnnotations([{ ...SERVED, language: null }]);
  assert.deepEqual(noteInLanguage(note, ['de']), { title: SERVED.title, text: SERVED.text, html: SERVED.html, lang: null });
  assert.equal(noteInLanguage(note, ['pt']).title, 'Borda dourada');
});

test('language tags are checked in their well-formed shape, as the server does', () => {
  for (const tag of ['en', 'pt-BR', 'zh-Hant-TW', 'sgn-BE-FR', 'x-klingon']) assert.ok(isLanguageTag(tag), tag);
  for (const tag of ['', 'pt_BR', 'en-', '-en', '1en', 'en-toolongsubtag', 'é', 'en GB', `a${'-abcdefgh'.repeat(4)}`]) {
    assert.ok(!isLanguageTag(tag), tag);
  }
});

test('the editor’s rows become the translations sent; empty rows are skipped', () => {
  const entries = [
    { n: 1, tag: ' pt ', title: ' Borda dourada ', text: 'A *borda*.' },
    { n: 2, tag: '', title: '', text: '  ' },
    { n: 3, tag: 'es', title: 'Borde', text: '   ' },
  ];
  assert.deepEqual(translationsOf(entries, 'en'), { pt: { title: 'Borda dourada', text: 'A *borda*.' }, es: { title: 'Borde', text: '' } });
  assert.deepEqual(translationsOf([], 'en'), {}, 'no rows: every translation removed');
});

test('a row the server would refuse is named before sending', () => {
  const row = { n: 2, tag: 'pt', title: 'Borda', text: '' };
  assert.equal(translationsOf([{ ...row, tag: '' }], 'en'), 'translation 2 has no language');
  assert.equal(translationsOf([{ ...row, title: '  ' }], 'en'), 'translation 2 has no title');
  assert.equal(translationsOf([{ ...row, tag: 'pt_BR' }], 'en'), '“pt_BR” is not a language tag such as es or pt-BR');
  assert.equal(translationsOf([{ ...row, tag: 'EN' }], 'en'), 'the note is already written in EN');
  assert.equal(translationsOf([row, { ...row, n: 3, tag: 'PT' }], 'en'), 'the language PT is listed twice');
  assert.deepEqual(translationsOf([{ ...row, tag: 'en' }], null), { en: { title: 'Borda', text: '' } }, 'no own language: any tag');
  const many = Array.from({ length: MAX_TRANSLATIONS + 1 }, (_, k) => ({ n: k + 1, tag: `x-l${k}`, title: 'T', text: '' }));
  assert.equal(translationsOf(many, 'en'), `a note can have at most ${MAX_TRANSLATIONS} translations`);
  assert.equal(Object.keys(/** @type {object} */ (translationsOf(many.slice(1), 'en'))).length, MAX_TRANSLATIONS);
});
