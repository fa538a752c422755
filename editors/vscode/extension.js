// The VS Code side of lensc's language server: starts `lensc lsp` (the
// binary named by the `lens.server.path` setting) for .lens files and
// hands it the editor's requests through vscode-languageclient.
'use strict';

const vscode = require('vscode');
const { LanguageClient } = require('vscode-languageclient/node');

let client;

function activate(context) {
  const command = vscode.workspace.getConfiguration('lens').get('server.path') || 'lensc';
  const serverOptions = {
    run: { command, args: ['lsp'] },
    debug: { command, args: ['lsp'] },
  };
  const clientOptions = {
    documentSelector: [
      { scheme: 'file', language: 'lens' },
      { scheme: 'untitled', language: 'lens' },
    ],
  };
  client = new LanguageClient('lens', 'lensc', serverOptions, clientOptions);
  context.subscriptions.push(client);
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
