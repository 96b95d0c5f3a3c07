-- Drives `hstlc lsp` from Neovim (0.7 APIs only: vim.lsp.start_client,
-- buf_attach_client, vim.diagnostic.get, vim.lsp.buf_request_sync).
-- Inputs (environment): HSTLC (the binary), SPEC (a malformed spec file), EXPECT_LINE,
-- EXPECT_COL, EXPECT_CODE (its first diagnostic, 0-based), FIX_LINE (0-based line to
-- replace) and FIX_TEXT (its fixed text), HOVER_LINE/HOVER_COL (on `always`), FORMATTED
-- (a file with the expected formatted text), RESULT (where "OK" is written at the end).
-- Any failure exits Neovim with status 1 and a message on stderr.

local function env(name)
  local v = os.getenv(name)
  if v == nil then error("missing environment variable " .. name) end
  return v
end

local function check(cond, msg)
  if not cond then error(msg, 2) end
end

local function main()
  local path = env("SPEC")
  vim.cmd("edit " .. vim.fn.fnameescape(path))
  local buf = vim.api.nvim_get_current_buf()
  local client_id = vim.lsp.start_client({
    name = "hstlc",
    cmd = { env("HSTLC"), "lsp" },
    root_dir = vim.fn.fnamemodify(path, ":h"),
  })
  check(client_id ~= nil, "vim.lsp.start_client failed")
  check(vim.lsp.buf_attach_client(buf, client_id), "buf_attach_client failed")

  -- The malformed spec: its diagnostic, at the right place, with its code.
  check(vim.wait(15000, function() return #vim.diagnostic.get(buf) > 0 end, 20),
    "no diagnostics arrived for the malformed spec")
  local d = vim.diagnostic.get(buf)[1]
  check(d.code == env("EXPECT_CODE"), "code: got " .. tostring(d.code))
  check(d.lnum == tonumber(env("EXPECT_LINE")) and d.col == tonumber(env("EXPECT_COL")),
    string.format("range start: got %d:%d", d.lnum, d.col))
  check(d.severity == vim.diagnostic.severity.ERROR, "severity: got " .. tostring(d.severity))

  -- Fix it in the buffer: the diagnostics clear.
  local row = tonumber(env("FIX_LINE"))
  vim.api.nvim_buf_set_lines(buf, row, row + 1, false, { env("FIX_TEXT") })
  check(vim.wait(15000, function() return #vim.diagnostic.get(buf) == 0 end, 20),
    "diagnostics did not clear after the fix: " .. vim.inspect(vim.diagnostic.get(buf)))

  -- Hover on `always`.
  local uri = vim.uri_from_bufnr(buf)
  local res = vim.lsp.buf_request_sync(buf, "textDocument/hover", {
    textDocument = { uri = uri },
    position = { line = tonumber(env("HOVER_LINE")), character = tonumber(env("HOVER_COL")) },
  }, 15000)
  check(res and res[client_id] and res[client_id].result, "no hover: " .. vim.inspect(res))
  local value = res[client_id].result.contents.value
  check(value:find("always", 1, true) and value:find("minimum", 1, true),
    "hover text: " .. tostring(value))

  -- Formatting: apply the edits, compare with the expected text.
  res = vim.lsp.buf_request_sync(buf, "textDocument/formatting", {
    textDocument = { uri = uri },
    options = { tabSize = 4, insertSpaces = true },
  }, 15000)
  check(res and res[client_id] and res[client_id].result, "no formatting: " .. vim.inspect(res))
  local edits = res[client_id].result
  check(#edits > 0, "formatting returned no edit")
  vim.lsp.util.apply_text_edits(edits, buf, "utf-16")
  local got = table.concat(vim.api.nvim_buf_get_lines(buf, 0, -1, false), "\n") .. "\n"
  local f = assert(io.open(env("FORMATTED"), "r"))
  local want = f:read("*a")
  f:close()
  check(got == want, "formatted buffer differs:\n" .. got .. "\n--- expected ---\n" .. want)

  vim.lsp.stop_client(client_id)
  vim.wait(5000, function() return vim.lsp.client_is_stopped(client_id) end, 20)
  local out = assert(io.open(env("RESULT"), "w"))
  out:write("OK\n")
  out:close()
end

local ok, err = pcall(main)
if not ok then
  io.stderr:write("nvim e2e: " .. tostring(err) .. "\n")
  vim.cmd("cquit 1")
else
  vim.cmd("qall!")
end
