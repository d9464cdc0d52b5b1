#!/usr/bin/env python3
"""Serves the page on 127.0.0.1 (standard library only): `www/` is the site's root, and the
repository's documentation beside it, so that the Help dialog's links resolve:

    /            -> www/index.html, and every other path -> www/<path>
    /docs/<file> -> docs/<file>   (the Markdown docs and their pictures)
    /README.md   -> README.md

Markdown is sent as `text/plain; charset=utf-8`, so the browser shows it rather than downloading
it. A path with `..` (or any other way out of its directory) is refused with 404, as is anything
not listed above. The end-to-end tests' server (`serve_one` in tests/e2e.rs) serves the same
layout.

Usage: python3 scripts/serve.py [--port 8000] [--bind 127.0.0.1]
"""

import argparse
import http.server
import pathlib
import posixpath
import sys
import urllib.parse

REPO = pathlib.Path(__file__).resolve().parent.parent
WWW = REPO / "www"
DOCS = REPO / "docs"
README = REPO / "README.md"


def resolve(url_path):
    """The file a request path maps to (see the module doc), or None (404)."""
    path = urllib.parse.unquote(urllib.parse.urlsplit(url_path).path)
    parts = [p for p in path.split("/") if p]
    if any(p in (".", "..") or "\\" in p or "\0" in p for p in parts):
        return None
    if parts == ["README.md"]:
        return README
    if parts[:1] == ["docs"]:
        root, rest = DOCS, parts[1:]
    else:
        root, rest = WWW, parts
    target = root.joinpath(*rest) if rest else root
    if target.is_dir():
        target = target / "index.html"
    try:
        target.resolve().relative_to(root.resolve())
    except ValueError:  # a symbolic link out of the directory
        return None
    return target if target.is_file() else None


class Handler(http.server.SimpleHTTPRequestHandler):
    """SimpleHTTPRequestHandler over the layout of `resolve`, with the page's content types."""

    extensions_map = {
        **http.server.SimpleHTTPRequestHandler.extensions_map,
        ".md": "text/plain; charset=utf-8",
        ".js": "text/javascript; charset=utf-8",
        ".html": "text/html; charset=utf-8",
        ".css": "text/css; charset=utf-8",
        ".wasm": "application/wasm",
        ".json": "application/json",
    }

    def send_head(self):
        if resolve(self.path) is None:
            self.send_error(404, "File not found")
            return None
        return super().send_head()

    def translate_path(self, path):
        return str(resolve(path))

    def list_directory(self, path):
        self.send_error(404, "File not found")
        return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--port", type=int, default=8000)
    parser.add_argument("--bind", default="127.0.0.1")
    args = parser.parse_args(argv)
    server = http.server.ThreadingHTTPServer((args.bind, args.port), Handler)
    print(f"scatterloc page: http://{args.bind}:{server.server_address[1]}/", flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
