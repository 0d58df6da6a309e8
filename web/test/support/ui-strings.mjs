// @ts-check
/**
 * A static scan of the viewer's sources for UI text written as a literal
 * instead of a catalogue key (src/i18n/). It reads the code as text, no
 * parser, and looks where visible text goes:
 *
 * - assignments to `textContent`, `innerText`, `title`, `placeholder`,
 *   `alt`, `ariaLabel` (the rest of the statement's line: `a ? 'x' : 'y'`);
 * - `setAttribute('aria-label' | 'title' | 'placeholder' | 'alt' |
 *   'aria-valuetext' | 'aria-description', …)`;
 * - `alert(…)`, `confirm(…)`, `prompt(…)`;
 * - element builders: the children arrays of `el(…)`, `h(…)` (and
 *   `append`, `replaceChildren`, `createTextNode`, `new Text`), and
 *   `title`, `aria-label`, `alt`, `placeholder` in their attribute objects;
 * - markup in string and template literals (`innerHTML`, SVG): text between
 *   tags and those attributes' values.
 *
 * A literal counts when, outside its `${…}` parts, it has a word of two or
 * more letters (so `·`, `X`, `≥ 90°` and numbers pass); a catalogue key
 * (`'measure.first'`) and the argument of `t(…)` never count.
 *
 * Its limits, on purpose kept simple: text that reaches a sink through a
 * variable or a function defined elsewhere (`const s = 'Hello'; el.textContent
 * = s`) is not seen; an assignment split over lines is read on its first line
 * only; `Error` messages (the reasons after a translated "Could not show
 * this model:") and text sent by the server are not UI literals here;
 * builders with other names than those above are not recognised. The test
 * plants literals of every kind to show that each rule fires.
 */

const LITERAL = /'(?:[^'\\\n]|\\.)*'|"(?:[^"\\\n]|\\.)*"|`(?:[^`\\]|\\.)*`/g;
const KEY = /^[a-z][a-zA-Z]*(\.[a-zA-Z]+)+$/;
const WORD = /\p{L}{2,}/u;

/**
 * The text a literal shows: quotes off, template slots out.
 * @param {string} literal with its quotes
 */
function shown(literal) {
  return literal.slice(1, -1).replace(/\$\{[^{}]*(\{[^{}]*\}[^{}]*)*\}/g, ' ');
}

/**
 * Literals in `code` that would show words, leaving out catalogue keys and
 * the arguments of `t(…)`.
 * @param {string} code
 * @param {ReadonlySet<string>} keys
 */
function wordyLiterals(code, keys) {
  const out = [];
  const text = code
    .replace(/\bt\(\s*(['"`])[^'"`]*\1/g, 't(')
    // Compared, not shown: `status === 'capped'`.
    .replace(/[!=]==?\s*('[^'\n]*'|"[^"\n]*")|('[^'\n]*'|"[^"\n]*")\s*[!=]==?/g, ' ');
  for (const match of text.matchAll(LITERAL)) {
    const words = shown(match[0]);
    if (keys.has(words) || KEY.test(words)) continue;
    if (WORD.test(words)) out.push(words);
  }
  return out;
}

/**
 * The argument text of the call whose `(` is at `open`, up to its matching `)`.
 * @param {string} source
 * @param {number} open
 */
function callArguments(source, open) {
  let depth = 0;
  for (let i = open; i < source.length; i++) {
    const c = source[i];
    if (c === '(' || c === '[' || c === '{') depth++;
    else if (c === ')' || c === ']' || c === '}') {
      depth--;
      if (depth === 0) return source.slice(open + 1, i);
    } else if (c === "'" || c === '"' || c === '`') {
      const literal = new RegExp(LITERAL.source, 'y');
      literal.lastIndex = i;
      const m = literal.exec(source);
      if (m) i += m[0].length - 1;
    }
  }
  return source.slice(open + 1);
}

/**
 * Arguments with every call in them (nested ones too) cut out.
 * @param {string} args
 */
function withoutCalls(args) {
  let before;
  do {
    before = args;
    args = args
      // Groups without literals (arrow parameters, `() => …`), then calls with what they hold.
      .replace(/\([^()'"`]*\)/g, ' ')
      .replace(/(?:\bnew\s+)?[a-zA-Z_$][\w$.]*\s*\((?:[^()'"`]|'[^'\n]*'|"[^"\n]*"|`[^`]*`)*\)/g, ' ');
  } while (args !== before);
  return args;
}

/**
 * @typedef {{ line: number, rule: string, text: string }} Finding
 * @param {string} source a file's text
 * @param {ReadonlySet<string>} [keys] the catalogue's keys
 * @returns {Finding[]}
 */
export function literalUiStrings(source, keys = new Set()) {
  /** @type {Finding[]} */
  const findings = [];
  const lineOf = (/** @type {number} */ at) => source.slice(0, at).split('\n').length;
  const add = (/** @type {number} */ at, /** @type {string} */ rule, /** @type {string} */ code) => {
    for (const text of wordyLiterals(code, keys)) findings.push({ line: lineOf(at), rule, text });
  };
  // Comments are not UI; their quotes would confuse the literal scan.
  const code = source.replace(/\/\*[\s\S]*?\*\//g, (c) => c.replace(/[^\n]/g, ' ')).replace(/(^|[^:'"`\\])\/\/[^\n]*/g, (c, lead) => lead + ' '.repeat(c.length - lead.length));

  for (const m of code.matchAll(/\.(textContent|innerText|title|placeholder|alt|ariaLabel)\s*=(?!=)([^;\n]*)/g)) {
    add(m.index, `.${m[1]} =`, m[2]);
  }
  for (const m of code.matchAll(/setAttribute\(\s*['"](aria-label|title|placeholder|alt|aria-valuetext|aria-description)['"]\s*,/g)) {
    add(m.index, `setAttribute('${m[1]}')`, callArguments(code, m.index + m[0].indexOf('(')).replace(/^[^,]*,/, ''));
  }
  for (const m of code.matchAll(/\b(alert|confirm|prompt)\(/g)) {
    add(m.index, `${m[1]}()`, callArguments(code, m.index + m[0].length - 1));
  }
  for (const m of code.matchAll(/(?:\b(?:el|h)|\.append|\.replaceChildren|\.prepend|createTextNode|new Text)\(/g)) {
    // Calls inside the arguments are read by their own match (a nested `el`) or
    // are a translation (`t(…)`): only this call's own literals count.
    const args = withoutCalls(callArguments(code, m.index + m[0].length - 1));
    // Children: the array arguments (builders) or the arguments themselves (append).
    const builder = /^(?:el|h)\(/.test(m[0]);
    const children = builder ? [...args.matchAll(/\[([^\]]*)\]/g)].map((a) => a[1]).join(',') : args;
    add(m.index, `${m[0]}…)`, children);
    if (builder) {
      for (const a of args.matchAll(/(?:\btitle|['"]aria-label['"]|\balt|\bplaceholder)\s*:([^,}]*)/g)) add(m.index, `${m[0]}{attribute})`, a[1]);
    }
  }
  for (const m of code.matchAll(LITERAL)) {
    const markup = m[0];
    if (!/<[a-zA-Z]/.test(markup)) continue;
    const body = shown(markup);
    for (const text of body.matchAll(/>([^<>]*)</g)) {
      if (WORD.test(text[1]) && !keys.has(text[1].trim())) findings.push({ line: lineOf(m.index), rule: 'markup text', text: text[1].trim() });
    }
    for (const a of body.matchAll(/\s(title|aria-label|alt|placeholder|aria-valuetext)="([^"]*)"/g)) {
      if (WORD.test(a[2])) findings.push({ line: lineOf(m.index), rule: `markup ${a[1]}=`, text: a[2] });
    }
  }
  return findings;
}

/**
 * The same for an HTML file: text between tags (outside `<script>` and
 * `<style>`) and the text attributes.
 * @param {string} html
 * @returns {Finding[]}
 */
export function literalHtmlStrings(html) {
  const body = html.replace(/<(script|style)\b[\s\S]*?<\/\1>/g, '');
  /** @type {Finding[]} */
  const findings = [];
  const lineOf = (/** @type {number} */ at) => body.slice(0, at).split('\n').length;
  for (const m of body.matchAll(/>([^<>]*)</g)) if (WORD.test(m[1])) findings.push({ line: lineOf(m.index), rule: 'html text', text: m[1].trim() });
  for (const m of body.matchAll(/\s(title|aria-label|alt|placeholder)="([^"]*)"/g)) if (WORD.test(m[2])) findings.push({ line: lineOf(m.index), rule: `html ${m[1]}=`, text: m[2] });
  return findings;
}
