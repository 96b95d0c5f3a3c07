#!/usr/bin/env python3
"""A hostile client for `hstlc lsp`, for the by-hand memory figures of issue 11 (class 4).

Peak and current RSS come from /proc/PID/status (Linux), CPU time from /proc/PID/stat.

    bench/lsp_probe.py BIN header           # Content-Length 10^12 and 2^64-1
    bench/lsp_probe.py BIN symbols MB       # documentSymbol on a generated MB-megabyte spec
                                            # (SPLIT=1: time the diagnostics apart)
    bench/lsp_probe.py BIN slow N SAMPLES   # N changes (+ hovers; NOHOVER=1: none) of a
                                            # 2,000-let spec, never reading; RSS every 10 s
    bench/lsp_probe.py BIN burst            # 200 changes and a hover in one write
"""
import json, os, subprocess, sys, threading, time

BIN = sys.argv[1]
CASE = sys.argv[2]


def frame(obj):
    body = json.dumps(obj).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


def cpu(pid):
    f = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK")


def hwm(pid):
    try:
        print("    cpu %.2fs" % cpu(pid))
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith(("VmHWM", "VmRSS")):
                    print("   ", line.strip())
    except FileNotFoundError:
        print("    (gone)")


def big_spec(lines):
    out = ["/// Generated.\nspec Big {\n    state {\n"]
    for v in range(4):
        out.append(f"        v{v}: int in 0..=9,\n")
    out.append("    }\n")
    for i in range(lines):
        a, b = i % 4, (i + 1) % 4
        if i >= 3 and i % 3 == 0:
            out.append(f"    let L{i} = L{(i // 3) % 97 * 3 + 1} || (v{a} + {i % 7} > v{b} && abs(v{a} - 3) < 2.5);\n")
        else:
            out.append(f"    let L{i} = {i % 5} < v{a} < {5 + i % 5} && v{b} >= {i % 3}; // region {i}\n")
    out.append(f"    task always[0..] (eventually[0..40] L{lines - 1});\n")
    out.append("}\n")
    return "".join(out)


class Reader(threading.Thread):
    def __init__(self, stream):
        super().__init__(daemon=True)
        self.stream = stream
        self.messages = []
        self.cv = threading.Condition()

    def run(self):
        while True:
            length = None
            while True:
                line = self.stream.readline()
                if not line:
                    return
                line = line.strip()
                if not line:
                    break
                if line.lower().startswith(b"content-length:"):
                    length = int(line.split(b":")[1])
            body = self.stream.read(length)
            with self.cv:
                self.messages.append(json.loads(body))
                self.cv.notify_all()

    def wait_id(self, i, timeout=600):
        end = time.time() + timeout
        with self.cv:
            while True:
                for m in self.messages:
                    if m.get("id") == i and "method" not in m:
                        return m
                left = end - time.time()
                if left <= 0:
                    return None
                self.cv.wait(left)


def start(read=True):
    p = subprocess.Popen([BIN, "lsp"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    r = None
    if read:
        r = Reader(p.stdout)
        r.start()
    threading.Thread(target=lambda: sys.stderr.buffer.write(b"[stderr] " + p.stderr.read()[:2000] + b"\n"), daemon=True).start()
    return p, r


def init(p, r):
    p.stdin.write(frame({"jsonrpc": "2.0", "id": 0, "method": "initialize", "params": {"capabilities": {}}}))
    p.stdin.write(frame({"jsonrpc": "2.0", "method": "initialized", "params": {}}))
    p.stdin.flush()
    if r:
        print("init:", bool(r.wait_id(0, 10)))


URI = "file:///tmp/big.hstl"

if CASE == "header":
    for n in [b"1000000000000", b"18446744073709551615"]:
        p, r = start()
        init(p, r)
        try:
            p.stdin.write(b"Content-Length: " + n + b"\r\n\r\n{}")
            p.stdin.write(frame({"jsonrpc": "2.0", "id": 5, "method": "shutdown"}))
            p.stdin.flush()
        except BrokenPipeError:
            print("broken pipe")
        time.sleep(2)
        print(n, "answer after:", r.wait_id(5, 3), "exit:", p.poll())
        hwm(p.pid)
        p.kill()
elif CASE == "symbols":
    mb = float(sys.argv[3]) if len(sys.argv) > 3 else 10
    text = big_spec(int(mb * 1e6 / 62))
    print("document bytes:", len(text))
    p, r = start()
    init(p, r)
    t = time.time()
    p.stdin.write(frame({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": URI, "languageId": "hstl", "version": 1, "text": text}}}))
    p.stdin.flush()
    if os.environ.get("SPLIT"):
        with r.cv:
            while not any(m.get("method") == "textDocument/publishDiagnostics" for m in r.messages):
                r.cv.wait(1)
        print("diagnostics after %.1fs, server cpu %.2fs" % (time.time() - t, cpu(p.pid)))
        t = time.time()
    p.stdin.write(frame({"jsonrpc": "2.0", "id": 1, "method": "textDocument/documentSymbol", "params": {"textDocument": {"uri": URI}}}))
    p.stdin.flush()
    m = r.wait_id(1)
    print("answered:", m is not None and ("result" in m), "in %.1fs" % (time.time() - t), (str(m)[:200] if m else ""))
    if m and isinstance(m.get("result"), list) and m["result"]:
        print("symbols:", len(m["result"][0].get("children", [])))
    hwm(p.pid)
    p.stdin.write(frame({"jsonrpc": "2.0", "id": 2, "method": "shutdown"}))
    p.stdin.write(frame({"jsonrpc": "2.0", "method": "exit"}))
    p.stdin.flush()
    print("exit status", p.wait(timeout=120))
elif CASE == "slow":
    # Many diagnostics per version, the client never reads.
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 2000
    base = "spec S {\n    state { x: int in 0..=3 }\n" + "".join(f"    let A{i} = y{i} > 1;\n" for i in range(2000)) + "    task always A0;\n}\n"
    p, _ = start(read=False)
    init(p, None)
    p.stdin.write(frame({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": URI, "languageId": "hstl", "version": 1, "text": base}}}))
    p.stdin.flush()
    def writer():
        try:
            for v in range(n):
                p.stdin.write(frame({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {"textDocument": {"uri": URI, "version": v + 2}, "contentChanges": [{"text": base + f"// {v}\n"}]}}))
                if not os.environ.get("NOHOVER"): p.stdin.write(frame({"jsonrpc": "2.0", "id": 100 + v, "method": "textDocument/hover", "params": {"textDocument": {"uri": URI}, "position": {"line": 2, "character": 9}}}))
                p.stdin.flush()
        except BrokenPipeError:
            pass
    w = threading.Thread(target=writer, daemon=True)
    w.start()
    for k in range(int(sys.argv[4]) if len(sys.argv) > 4 else 6):
        time.sleep(10)
        print("t=%ds writer alive=%s" % ((k + 1) * 10, w.is_alive()))
        hwm(p.pid)
    p.kill()
elif CASE == "burst":
    p, r = start()
    init(p, r)
    base = "spec S {\n    state { x: int in 0..=3 }\n    let A = x > 1;\n    task always A;\n}\n"
    p.stdin.write(frame({"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {"uri": URI, "languageId": "hstl", "version": 1, "text": base}}}))
    buf = b""
    for v in range(200):
        buf += frame({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {"textDocument": {"uri": URI, "version": v + 2}, "contentChanges": [{"text": base + f"// {v}\n"}]}})
    buf += frame({"jsonrpc": "2.0", "id": 7, "method": "textDocument/hover", "params": {"textDocument": {"uri": URI}, "position": {"line": 2, "character": 8}}})
    p.stdin.write(buf)
    p.stdin.flush()
    m = r.wait_id(7)
    time.sleep(0.5)
    pubs = [x for x in r.messages if x.get("method") == "textDocument/publishDiagnostics"]
    print("hover ok:", m is not None and "result" in m, "publishes:", len(pubs))
    p.kill()
