#!/usr/bin/env python3
"""The renderer's shape, measured: long functions, long files and import circles in src/.

Run from the repository root:  python3 tools/code-shape.py [--max-function-lines 80]
                                   [--max-file-lines 600] [--max-functions N] [--max-files N]
                                   [--max-circles N]

It prints three sections, each closed by a count line that a closing note can quote:

  functions over 80 lines: N   every `fn` in src/**/*.rs whose body, from the line of its
                               opening brace to the line of its closing brace, spans more than
                               80 lines (path:line name length, the line being the `fn`'s);
                               a signature wrapped over several lines, attributes and doc
                               comments do not count, nested fns count on their own and inside
                               their parent. (This is how "The renderer's shape" counted its
                               33 at 2c43c3b; from the `fn` line it would be 34.)
  files over 600 lines: M      every .rs file in src/ with more than 600 lines.
  import circles: K            every strongly connected component of more than one file in
                               the graph file -> file built from the paths the code names.

How the graph is built (the rule, so the numbers can be argued with):
  * The module tree is read from `mod x;` declarations (with `#[path]`), starting at
    src/lib.rs (the library, `crate::` there) and src/main.rs (the binary, whose `crate::`
    is main.rs and which reaches the library as `fovea::`). Inline `mod x { ... }` blocks are
    modules of the file they sit in (so `use super::*` in a test module is no edge).
  * Every path in a `use` item and every `crate::`, `super::`, `self::` (and `fovea::` in the
    binary) path in code is resolved: its leading segments are walked down the module tree;
    the first segment that is not a module names an item, and the edge goes to the file
    that defines that item. A module that re-exports the item (`pub use a::Item;`, or
    `pub use a::*` when the file behind `a` defines `Item`) is looked through, so a
    `mod.rs` that merely re-exports is never the target; a module whose file neither defines
    nor re-exports the item (a macro, a variant we failed to see) is the target itself.
    A path that stops at a module (`use crate::bench;`, `use super::*`'s module) is an
    edge to that module's file when it is a glob; a module imported by name is an alias,
    and the paths through it in code (`bench::run(..)`) are resolved as above. Bare paths
    through a child module (`runner::run(..)` in the parent) are resolved too.
  * A `pub use` is a re-export, not a use: it makes an edge from its file only when the
    file's own code also names what it re-exports.
  * Edges from a file to itself are dropped; extern crates are not in the graph.

Standard library only. The lexer blanks comments, strings and char literals, which is
enough for this code base; it is a measure, not a Rust parser.
"""

import argparse
import os
import re
import sys

SRC = "src"


# ---------------------------------------------------------------------------- lexing


def blank_comments_and_strings(text):
    """The text with comments, strings and char literals replaced by spaces (newlines kept),
    so braces, `fn`, `use` and `::` inside them do not count."""
    out = []
    i = 0
    n = len(text)

    def blank(segment):
        return "".join(c if c == "\n" else " " for c in segment)

    while i < n:
        c = text[i]
        nxt = text[i + 1] if i + 1 < n else ""
        if c == "/" and nxt == "/":
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(blank(text[i:j]))
            i = j
        elif c == "/" and nxt == "*":
            depth = 0
            j = i
            while j < n:
                if text.startswith("/*", j):
                    depth += 1
                    j += 2
                elif text.startswith("*/", j):
                    depth -= 1
                    j += 2
                    if depth == 0:
                        break
                else:
                    j += 1
            out.append(blank(text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and not _ident_before(text, i):
            m = re.match(r'r(#*)"', text[i:])
            hashes = m.group(1)
            end = text.find('"' + hashes, i + len(m.group(0)))
            end = n if end < 0 else end + 1 + len(hashes)
            out.append(blank(text[i:end]))
            i = end
        elif c == "b" and nxt in "\"'" and not _ident_before(text, i):
            out.append(" ")
            i += 1
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(blank(text[i:j + 1]))
            i = j + 1
        elif c == "'":
            # A char literal ('a', '\n', '\u{1F600}') or a lifetime ('a).
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'", text[i:])
            if m:
                out.append(blank(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def _ident_before(text, i):
    return i > 0 and (text[i - 1].isalnum() or text[i - 1] == "_")


def line_of(text, pos, _cache={}):
    key = id(text)
    starts = _cache.get(key)
    if starts is None or starts[0] is not text:
        offsets = [0] + [m.end() for m in re.finditer("\n", text)]
        starts = (text, offsets)
        _cache[key] = starts
    import bisect

    return bisect.bisect_right(starts[1], pos)


def matching_brace(code, open_pos):
    depth = 0
    for j in range(open_pos, len(code)):
        ch = code[j]
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code) - 1


# ---------------------------------------------------------------------------- functions


FN_RE = re.compile(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)")


def long_functions(path, code, limit):
    found = []
    for m in FN_RE.finditer(code):
        body = function_body_start(code, m.end())
        if body is None:
            continue
        end = matching_brace(code, body)
        length = line_of(code, end) - line_of(code, body) + 1
        if length > limit:
            found.append((path, line_of(code, m.start()), m.group(1), length))
    return found


def function_body_start(code, pos):
    """The `{` that opens the body of the fn whose signature starts at `pos`, or None for a
    declaration without a body (`fn f();` in a trait)."""
    parens = 0
    for j in range(pos, len(code)):
        ch = code[j]
        if ch in "([":
            parens += 1
        elif ch in ")]":
            parens -= 1
        elif parens == 0 and ch == ";":
            return None
        elif parens == 0 and ch == "{":
            return j
    return None


# ---------------------------------------------------------------------------- module tree


class Source:
    """One .rs file: its text, the scopes (modules) inside it, its `use` items."""

    def __init__(self, path):
        self.path = path
        with open(path, encoding="utf-8") as f:
            self.raw = f.read()
        self.code = blank_comments_and_strings(self.raw)
        self.lines = self.raw.count("\n") + (0 if self.raw.endswith("\n") else 1)
        self.crate = None
        self.modpath = None  # the module path of the file itself
        self.inline = []  # (start, end, modpath) of inline `mod x { }` blocks
        self.uses = []  # Use
        self.use_spans = []

    def scope_at(self, pos):
        """The module path in effect at `pos` (the innermost inline module, else the file)."""
        best = self.modpath
        best_start = -1
        for start, end, modpath in self.inline:
            if start <= pos <= end and start > best_start:
                best, best_start = modpath, start
        return best


class Use:
    def __init__(self, source, scope, segments, alias, public, pos):
        self.source = source
        self.scope = scope
        self.segments = segments  # ["crate", "bench", "runner", "run"] or [..., "*"]
        self.alias = alias  # the name it brings into scope (None for a glob)
        self.public = public
        self.pos = pos


MOD_DECL_RE = re.compile(
    r"(?:\bpub\s*(?:\([^)]*\))?\s*)?\bmod\s+([A-Za-z_][A-Za-z0-9_]*)\s*([;{])"
)


class Crate:
    def __init__(self, name, root):
        self.name = name
        self.root = root
        self.modules = {}  # tuple module path -> Source
        self.children = {}  # tuple module path -> {name: tuple module path}


def load_crate(name, root_path, sources):
    crate = Crate(name, root_path)
    visit(crate, root_path, (), os.path.dirname(root_path), sources)
    return crate


def visit(crate, path, modpath, child_dir, sources):
    """Reads `path` as module `modpath`; its `mod x;` files live in `child_dir`."""
    if path not in sources:
        sources[path] = Source(path)
    src = sources[path]
    src.crate = crate
    src.modpath = modpath
    crate.modules[modpath] = src
    crate.children.setdefault(modpath, {})
    for m in MOD_DECL_RE.finditer(src.code):
        name, kind = m.group(1), m.group(2)
        parent = src.scope_at(m.start())
        child = parent + (name,)
        crate.children.setdefault(parent, {})[name] = child
        if kind == "{":
            open_pos = m.end() - 1
            src.inline.append((open_pos, matching_brace(src.code, open_pos), child))
            crate.modules[child] = src
            crate.children.setdefault(child, {})
            continue
        if parent != modpath:
            continue  # `mod x;` inside an inline module: not used here
        attr = re.search(r'#\[path\s*=\s*"([^"]+)"\]\s*(?:#\[[^\]]*\]\s*)*$', src.raw[: m.start()])
        if attr:
            file = os.path.normpath(os.path.join(os.path.dirname(path), attr.group(1)))
            visit(crate, file, child, os.path.join(os.path.dirname(file), name), sources)
            continue
        flat = os.path.join(child_dir, name + ".rs")
        nested = os.path.join(child_dir, name, "mod.rs")
        if os.path.exists(flat):
            visit(crate, flat, child, os.path.join(child_dir, name), sources)
        elif os.path.exists(nested):
            visit(crate, nested, child, os.path.join(child_dir, name), sources)


# ---------------------------------------------------------------------------- use items


USE_RE = re.compile(r"(?:\b(pub)\s*(?:\([^)]*\))?\s*)?\buse\s+([^;]*);")


def parse_use_tree(text):
    """`a::{b, c::{d as e, self}, f::*}` -> [(["a","b"], "b"), (["a","c","d"], "e"),
    (["a","c"], "c"), (["a","f","*"], None)]."""
    tokens = re.findall(r"::|[A-Za-z_][A-Za-z0-9_]*|\*|\{|\}|,", text)
    pos = 0

    def tree(prefix):
        nonlocal pos
        results = []
        segments = list(prefix)
        while pos < len(tokens):
            tok = tokens[pos]
            if tok == "::":
                pos += 1
            elif tok == "{":
                pos += 1
                while pos < len(tokens) and tokens[pos] != "}":
                    if tokens[pos] == ",":
                        pos += 1
                        continue
                    results.extend(tree(segments))
                pos += 1
                return results
            elif tok in ",}":
                break
            elif tok == "*":
                pos += 1
                return results + [(segments + ["*"], None)]
            elif tok == "as":
                alias = tokens[pos + 1]
                pos += 2
                return results + [(segments, alias)]
            elif tok == "self" and prefix and segments == list(prefix):
                pos += 1  # `a::{self, b}`: the module `a` itself
                alias = segments[-1]
                if pos < len(tokens) and tokens[pos] == "as":
                    alias = tokens[pos + 1]
                    pos += 2
                return results + [(segments, alias)]
            else:
                segments.append(tok)
                pos += 1
        if segments and len(segments) > len(prefix):
            results.append((segments, segments[-1]))
        return results

    return tree([])


def read_uses(src):
    for m in USE_RE.finditer(src.code):
        src.use_spans.append((m.start(), m.end()))
        scope = src.scope_at(m.start())
        for segments, alias in parse_use_tree(m.group(2)):
            if segments and segments[0] == "":
                segments = segments[1:]
            src.uses.append(Use(src, scope, segments, alias, m.group(1) == "pub", m.start()))


# ---------------------------------------------------------------------------- resolution


ITEM_DEF = r"\b(?:struct|enum|union|fn|trait|type|const|static|mod|macro_rules!)\s+{}\b"


class Resolver:
    def __init__(self, lib, binary):
        self.lib = lib
        self.binary = binary

    def start(self, crate, scope, first):
        """The module a path's first segment names, or None for an extern crate."""
        if first == "crate":
            return crate, ()
        if first == "self":
            return crate, scope
        if first == "super":
            return crate, scope[:-1]
        if first == "fovea" and crate is self.binary:
            return self.lib, ()
        if first in crate.children.get(scope, {}):
            return crate, crate.children[scope][first]
        return None

    def resolve(self, crate, scope, segments, depth=0):
        """('item', file) for a path to an item, ('module', crate, modpath) for a path that
        stops at a module, or None (extern, or not understood)."""
        if not segments or depth > 12:
            return None
        first = self.start(crate, scope, segments[0])
        if first is None:
            return None
        crate, modpath = first
        rest = segments[1:]
        while rest and rest[0] == "super":
            modpath, rest = modpath[:-1], rest[1:]
        while rest:
            seg = rest[0]
            if seg == "*":
                return ("module", crate, modpath)
            children = crate.children.get(modpath, {})
            if seg in children:
                modpath, rest = children[seg], rest[1:]
                continue
            return ("item", self.item_file(crate, modpath, seg, depth))
        return ("module", crate, modpath)

    def item_file(self, crate, modpath, name, depth):
        """The file that defines `name` as seen from module `modpath`, looking through
        re-exports."""
        src = crate.modules.get(modpath)
        if src is None:
            return None
        for use in src.uses:
            if use.public and use.scope == modpath and use.alias == name:
                found = self.resolve(crate, modpath, use.segments, depth + 1)
                if found and found[0] == "item" and found[1]:
                    return found[1]
                if found and found[0] == "module":
                    return found[1].modules[found[2]].path
        if re.search(ITEM_DEF.format(re.escape(name)), src.code):
            return src.path
        for use in src.uses:
            if use.public and use.scope == modpath and use.segments[-1:] == ["*"]:
                found = self.resolve(crate, modpath, use.segments, depth + 1)
                if found and found[0] == "module":
                    target = found[1].modules[found[2]]
                    inner = self.item_file(found[1], found[2], name, depth + 1)
                    if inner and inner != src.path and (inner != target.path or re.search(
                            ITEM_DEF.format(re.escape(name)), target.code)):
                        return inner
        return src.path


CODE_PATH_RE = re.compile(
    r"(?<![A-Za-z0-9_:])([A-Za-z_][A-Za-z0-9_]*)((?:\s*::\s*(?:<[^;{}]*?>\s*::\s*)?[A-Za-z_][A-Za-z0-9_]*)+)"
)


def edges_of(src, resolver):
    """The files `src` depends on, each with the first line that names it."""
    crate = src.crate
    edges = {}

    def add(target, pos):
        if target and target != src.path and target not in edges:
            edges[target] = line_of(src.code, pos)

    aliases = {}  # (scope, name) -> (crate, modpath)
    for use in src.uses:
        found = resolver.resolve(crate, use.scope, use.segments)
        if found is None:
            continue
        if found[0] == "module":
            if use.segments[-1] == "*":
                add(found[1].modules[found[2]].path, use.pos)
            elif use.alias:
                aliases[(use.scope, use.alias)] = (found[1], found[2])
            continue
        if use.public and not names_outside_uses(src, use.alias):
            continue  # a re-export only
        add(found[1], use.pos)

    for m in CODE_PATH_RE.finditer(src.code):
        if any(start <= m.start() < end for start, end in src.use_spans):
            continue
        first = m.group(1)
        rest = [s for s in re.findall(r"[A-Za-z_][A-Za-z0-9_]*", re.sub(r"<[^;{}]*?>", " ", m.group(2)))]
        scope = src.scope_at(m.start())
        alias = lookup_alias(aliases, scope, first)
        if alias:
            alias_crate, modpath = alias
            found = resolve_from(resolver, alias_crate, modpath, rest)
        elif first in ("crate", "super", "self", "fovea") or first in crate.children.get(scope, {}):
            found = resolver.resolve(crate, scope, [first] + rest)
        else:
            continue
        if found and found[0] == "item":
            add(found[1], m.start())
    return edges


def lookup_alias(aliases, scope, name):
    while True:
        if (scope, name) in aliases:
            return aliases[(scope, name)]
        if not scope:
            return None
        scope = scope[:-1]


def resolve_from(resolver, crate, modpath, rest):
    """Resolves `rest` below module `modpath` (a path through an imported module)."""
    while rest:
        children = crate.children.get(modpath, {})
        if rest[0] in children:
            modpath, rest = children[rest[0]], rest[1:]
            continue
        return ("item", resolver.item_file(crate, modpath, rest[0], 0))
    return ("module", crate, modpath)


def names_outside_uses(src, name):
    if not name:
        return False
    declared = {m.start(1) for m in MOD_DECL_RE.finditer(src.code)}
    for m in re.finditer(r"\b{}\b".format(re.escape(name)), src.code):
        if m.start() in declared:
            continue  # `pub mod run;` beside `pub use run::run;` does not use `run`
        if not any(start <= m.start() < end for start, end in src.use_spans):
            return True
    return False


def circles(graph):
    """Tarjan's strongly connected components with more than one node, iteratively."""
    index, low, on_stack, stack, result = {}, {}, set(), [], []
    counter = [0]
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in graph:
                    continue
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    top = stack.pop()
                    on_stack.discard(top)
                    component.append(top)
                    if top == node:
                        break
                if len(component) > 1:
                    result.append(sorted(component))
    return sorted(result)


# ---------------------------------------------------------------------------- report


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--max-function-lines", type=int, default=80)
    parser.add_argument("--max-file-lines", type=int, default=600)
    parser.add_argument("--max-functions", type=int, help="fail if more long functions")
    parser.add_argument("--max-files", type=int, help="fail if more long files")
    parser.add_argument("--max-circles", type=int, help="fail if more import circles")
    parser.add_argument("--edges", action="store_true", help="also print every edge")
    args = parser.parse_args()
    if not os.path.isdir(SRC):
        sys.exit("run from the repository root (no src/ here)")

    sources = {}
    lib = load_crate("lib", os.path.join(SRC, "lib.rs"), sources)
    binary = load_crate("bin", os.path.join(SRC, "main.rs"), sources)
    all_files = sorted(
        os.path.join(d, f) for d, _, fs in os.walk(SRC) for f in fs if f.endswith(".rs")
    )
    for path in all_files:
        if path not in sources:
            sources[path] = Source(path)  # not in the module tree: measured, no edges
    for src in sources.values():
        read_uses(src)

    functions = []
    for path in all_files:
        functions.extend(long_functions(path, sources[path].code, args.max_function_lines))
    functions.sort(key=lambda f: (-f[3], f[0], f[1]))
    print(f"## functions over {args.max_function_lines} lines")
    for path, line, name, length in functions:
        print(f"{path}:{line} {name} {length}")
    print(f"functions over {args.max_function_lines} lines: {len(functions)}\n")

    files = sorted(
        ((sources[p].lines, p) for p in all_files if sources[p].lines > args.max_file_lines),
        reverse=True,
    )
    print(f"## files over {args.max_file_lines} lines")
    for lines, path in files:
        print(f"{path} {lines}")
    print(f"files over {args.max_file_lines} lines: {len(files)}\n")

    resolver = Resolver(lib, binary)
    graph = {}
    lines = {}
    for path in all_files:
        src = sources[path]
        if src.crate is None:
            graph[path] = set()
            continue
        edges = edges_of(src, resolver)
        graph[path] = set(edges)
        for target, line in edges.items():
            lines[(path, target)] = line
    if args.edges:
        print("## edges")
        for path in all_files:
            for target in sorted(graph[path]):
                print(f"{path}:{lines[(path, target)]} -> {target}")
        print()
    found = circles(graph)
    print("## import circles")
    for component in found:
        members = set(component)
        print(" <-> ".join(component))
        for a in component:
            for b in sorted(graph[a] & members):
                print(f"    {a}:{lines[(a, b)]} -> {b}")
    print(f"import circles: {len(found)}")

    failed = [
        label
        for label, count, limit in (
            ("functions", len(functions), args.max_functions),
            ("files", len(files), args.max_files),
            ("circles", len(found), args.max_circles),
        )
        if limit is not None and count > limit
    ]
    if failed:
        sys.exit("over the limit: " + ", ".join(failed))


if __name__ == "__main__":
    main()
