#!/usr/bin/env python3
"""Check every local link of the built manual, and that every page and example is reachable.

Usage: check_manual_links.py [HTML_DIR]   (default build/doc-html)

1. Links: every href/src of every built page that has no URL scheme must name an existing
   file or folder (pages, images, downloads, and the repository paths that doc/conf.py
   resolves into the checkout), and a "#anchor" must exist as an id in the target page.
   http(s) links are not checked: the build machine has no internet access.
2. Reachability: starting from index.html and following local links, every doc/*.md and
   doc/guide/*.md page (doc/README.md aside: it is the repository's pointer to the manual)
   must be reached, and every examples/<name>/ folder must be linked from a reached page.
3. doc/README.md names every page of doc/ (it is what a reader of the repository sees).

Prints one line per problem and exits 1 when there is any; 0 otherwise.
"""
import os
import sys
from html.parser import HTMLParser
from urllib.parse import unquote, urlsplit

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOC = os.path.join(REPO, "doc")


class Links(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.links, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for key in ("id", "name"):
            if a.get(key):
                self.ids.add(a[key])
        for key in ("href", "src"):
            if a.get(key) is not None and tag in ("a", "img", "link", "script", "source"):
                self.links.append(a[key])


def parse(path, cache={}):
    if path not in cache:
        p = Links()
        with open(path, encoding="utf-8", errors="replace") as f:
            p.feed(f.read())
        cache[path] = p
    return cache[path]


def main():
    out = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(REPO, "build", "doc-html"))
    if not os.path.isfile(os.path.join(out, "index.html")):
        print(f"{out}/index.html: missing (build the manual first)")
        return 1
    problems = []
    pages = []
    for root, dirs, files in os.walk(out):
        dirs[:] = [d for d in dirs if not d.startswith("_")]  # _static, _sources, _images
        pages += [os.path.join(root, f) for f in files if f.endswith(".html")]

    graph = {}
    for page in sorted(pages):
        rel = os.path.relpath(page, out)
        targets = []
        for link in parse(page).links:
            parts = urlsplit(link)
            if parts.scheme or link.startswith("//"):
                continue  # http(s), mailto, javascript, data: not checked offline
            path = unquote(parts.path)
            target = os.path.normpath(os.path.join(os.path.dirname(page), path)) if path else page
            if not os.path.exists(target):
                problems.append(f"{rel}: broken link {link}")
                continue
            targets.append(target)
            if parts.fragment and target.endswith(".html") and os.path.isfile(target):
                if unquote(parts.fragment) not in parse(target).ids:
                    problems.append(f"{rel}: anchor not found: {link}")
        graph[page] = targets

    # reachability from the index
    seen, todo, linked = set(), [os.path.join(out, "index.html")], set()
    while todo:
        page = todo.pop()
        if page in seen:
            continue
        seen.add(page)
        for t in graph.get(page, []):
            linked.add(t)
            if t.endswith(".html") and t in graph:
                todo.append(t)

    md_pages = [f for f in os.listdir(DOC) if f.endswith((".md", ".rst")) and f not in ("README.md", "index.rst")]
    guide = os.path.join(DOC, "guide")
    if os.path.isdir(guide):
        md_pages += ["guide/" + f for f in os.listdir(guide) if f.endswith((".md", ".rst"))]
    for md in sorted(md_pages):
        html = os.path.join(out, os.path.splitext(md)[0] + ".html")
        if html not in seen:
            problems.append(f"doc/{md}: not reachable from the manual's index")

    examples = os.path.join(REPO, "examples")
    for name in sorted(os.listdir(examples)) if os.path.isdir(examples) else []:
        folder = os.path.join(examples, name)
        if not os.path.isdir(folder):
            continue
        if not any(t == folder or t.startswith(folder + os.sep) for t in linked):
            problems.append(f"examples/{name}/: not linked from any page reachable from the index")

    readme = os.path.join(DOC, "README.md")
    if os.path.isfile(readme):
        text = open(readme, encoding="utf-8").read()
        for md in sorted(md_pages):
            if md not in text:
                problems.append(f"doc/README.md: does not name doc/{md}")

    for p in problems:
        print(p)
    print(f"check_manual_links: {len(pages)} pages, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
