-- lensc in Neovim 0.7 and later: the `.lens` filetype, `//` comments and
-- the language server (`lensc lsp`, which must be on PATH), with hover on
-- `K` and go to definition on `gd` in `.lens` buffers. Load it from your
-- init.lua (`dofile('/path/to/lensc/editors/nvim/lensc.lua')`) or copy it
-- there. Tested headless on Debian 12's Neovim 0.7.2 (tests/it/editors.rs).

-- Neovim 0.7 reads filetypes from filetype.vim unless told otherwise; an
-- autocommand works in every version.
vim.cmd([[autocmd BufRead,BufNewFile *.lens setfiletype lens]])

local client_id = nil

local function root_of(buf)
  local file = vim.api.nvim_buf_get_name(buf)
  local dir = vim.fn.fnamemodify(file, ':p:h')
  local git = vim.fn.finddir('.git', dir .. ';')
  if git ~= '' then
    return vim.fn.fnamemodify(git, ':p:h:h')
  end
  return dir
end

vim.api.nvim_create_autocmd('FileType', {
  pattern = 'lens',
  callback = function(args)
    local buf = args.buf
    vim.bo[buf].commentstring = '// %s'
    local config = { name = 'lensc', cmd = { 'lensc', 'lsp' }, root_dir = root_of(buf) }
    if vim.lsp.start then
      -- 0.8 and later: starts the server once per root, attaches the buffer.
      vim.lsp.start(config)
    else
      -- 0.7: one client for the session, each buffer attached to it.
      if client_id == nil then
        client_id = vim.lsp.start_client(config)
      end
      vim.lsp.buf_attach_client(buf, client_id)
    end
    -- Not defaults before 0.10 (K) or at all (gd): set for .lens buffers.
    vim.keymap.set('n', 'K', vim.lsp.buf.hover, { buffer = buf })
    vim.keymap.set('n', 'gd', vim.lsp.buf.definition, { buffer = buf })
  end,
})
