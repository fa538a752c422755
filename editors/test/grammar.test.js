// The TextMate grammar (editors/vscode/syntaxes/lens.tmLanguage.json) as VS Code runs it:
// vscode-textmate with the Oniguruma regex engine compiled to WebAssembly.
// Every example and standard-library file is tokenised line by line, and
// no token with text other than whitespace may be left with only the
// file's base scope; a few lines are checked scope by scope.
'use strict';

const { test } = require('node:test');
const assert = require('node:assert');
const fs = require('node:fs');
const path = require('node:path');
const vsctm = require('vscode-textmate');
const oniguruma = require('vscode-oniguruma');

const repo = path.resolve(__dirname, '..', '..');
const grammarPath = path.join(repo, 'editors', 'vscode', 'syntaxes', 'lens.tmLanguage.json');

async function loadGrammar() {
  const wasm = fs.readFileSync(path.join(path.dirname(require.resolve('vscode-oniguruma')), 'onig.wasm'));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  const registry = new vsctm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
      createOnigString: (s) => new oniguruma.OnigString(s),
    }),
    loadGrammar: async (scopeName) =>
      scopeName === 'source.lens'
        ? vsctm.parseRawGrammar(fs.readFileSync(grammarPath, 'utf8'), grammarPath)
        : null,
  });
  return registry.loadGrammar('source.lens');
}

const grammarReady = loadGrammar();

/// Every token of a text: its line, its text and its scopes.
function tokenise(grammar, text) {
  const out = [];
  let stack = vsctm.INITIAL;
  text.split(/\r?\n/).forEach((line, n) => {
    const r = grammar.tokenizeLine(line, stack);
    for (const t of r.tokens) {
      out.push({ line: n + 1, text: line.substring(t.startIndex, t.endIndex), scopes: t.scopes });
    }
    stack = r.ruleStack;
  });
  return out;
}

function lensFiles(dir) {
  return fs
    .readdirSync(path.join(repo, dir))
    .filter((f) => f.endsWith('.lens'))
    .sort()
    .map((f) => path.join(dir, f));
}

const files = [...lensFiles('examples'), ...lensFiles('stdlib')];

test('there are examples and standard-library files to tokenise', () => {
  assert.ok(lensFiles('examples').length >= 10, 'examples/');
  assert.strictEqual(lensFiles('stdlib').length, 4, 'stdlib/');
});

for (const file of files) {
  test(`every token of ${file} is scoped`, async () => {
    const grammar = await grammarReady;
    const tokens = tokenise(grammar, fs.readFileSync(path.join(repo, file), 'utf8'));
    const bare = tokens.filter((t) => t.scopes.length === 1 && t.text.trim() !== '');
    assert.deepStrictEqual(
      bare.map((t) => `${file}:${t.line}: ${JSON.stringify(t.text)}`),
      [],
      'text with only the base scope',
    );
    assert.ok(tokens.length > 20, `${file} has ${tokens.length} tokens`);
  });
}

/// The innermost scope of the first token whose text is `text`.
function scopeOf(tokens, text, nth = 0) {
  const found = tokens.filter((t) => t.text === text)[nth];
  assert.ok(found, `no token ${JSON.stringify(text)} in ${JSON.stringify(tokens.map((t) => t.text))}`);
  return found.scopes[found.scopes.length - 1];
}

test('keywords, names, kinds, parameters, numbers and their units', async () => {
  const grammar = await grammarReady;
  const t = tokenise(
    grammar,
    [
      'use std::machines::linuxcnc_lathe',
      'use "common.lens" // shared',
      'let depth = 2 * 5 um',
      'tool knife = round_nose { nose_radius: 85 µm, clearance: 10° }',
      'surface s = freeform {',
      '    z(x, y) = 0.02 mm * sin(5 rad/mm * x) /* wave */',
      '    domain: rect(x: 0 mm .. 6.283 mm, y: -1 mm .. 1 mm)',
      '}',
      'job j { surface: s, tool: knife }',
    ].join('\n'),
  );
  assert.strictEqual(scopeOf(t, 'use'), 'keyword.control.import.lens');
  assert.strictEqual(scopeOf(t, 'std::machines::linuxcnc_lathe'), 'entity.name.namespace.lens');
  assert.strictEqual(scopeOf(t, 'common.lens'), 'string.quoted.double.lens');
  assert.strictEqual(scopeOf(t, '// shared'), 'comment.line.double-slash.lens');
  assert.strictEqual(scopeOf(t, 'let'), 'storage.type.let.lens');
  assert.strictEqual(scopeOf(t, 'depth'), 'variable.other.constant.lens');
  assert.strictEqual(scopeOf(t, 'tool'), 'storage.type.lens');
  assert.strictEqual(scopeOf(t, 'knife'), 'entity.name.type.lens');
  assert.strictEqual(scopeOf(t, 'round_nose'), 'support.class.kind.lens');
  assert.strictEqual(scopeOf(t, 'nose_radius'), 'variable.parameter.lens');
  assert.strictEqual(scopeOf(t, '85'), 'constant.numeric.lens');
  assert.strictEqual(scopeOf(t, 'µm'), 'keyword.other.unit.lens');
  assert.strictEqual(scopeOf(t, '°'), 'keyword.other.unit.lens');
  assert.strictEqual(scopeOf(t, 'um'), 'keyword.other.unit.lens');
  assert.strictEqual(scopeOf(t, 'z'), 'entity.name.function.formula.lens');
  assert.strictEqual(scopeOf(t, 'sin'), 'support.function.math.lens');
  assert.strictEqual(scopeOf(t, 'rad/mm'), 'keyword.other.unit.lens');
  assert.strictEqual(scopeOf(t, '/*'), 'punctuation.definition.comment.begin.lens');
  assert.strictEqual(scopeOf(t, '..'), 'keyword.operator.range.lens');
  assert.strictEqual(scopeOf(t, 'rect'), 'support.class.kind.lens');
  // In a job's block, `surface:` and `tool:` are parameters, not keywords.
  assert.strictEqual(scopeOf(t, 'surface', 1), 'variable.parameter.lens');
  assert.strictEqual(scopeOf(t, 'job'), 'keyword.other.job.lens');
});

test('a division with spaces is no unit', async () => {
  const grammar = await grammarReady;
  const t = tokenise(grammar, 'let a = 1 mm / 2\nlet b = 3 c');
  assert.strictEqual(scopeOf(t, 'mm'), 'keyword.other.unit.lens');
  assert.strictEqual(scopeOf(t, '2'), 'constant.numeric.lens');
  // The grammar reads `3 c` as a number and its unit, as lensc's parser does.
  assert.strictEqual(scopeOf(t, 'c'), 'keyword.other.unit.lens');
});
