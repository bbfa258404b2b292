#!/usr/bin/env python3
"""Lists every C++ function longer than a limit (80 lines by default).

Usage: tools/check_function_length.py [--max N] [--exclude FILE] [--all] PATH...

PATH is a file or a folder (searched for .cpp/.hpp/.h/.cc). A function's
length runs from the first line of its signature to its closing brace. Member
functions defined in class bodies are functions; a lambda inside a function
counts toward that function; a lambda bound to a name at namespace scope is a
function of its own. Exits 1 when a function is too long, 0 otherwise.

The exclusion file lists paths (a folder prefix ending in '/', or a file), one
a line, '#' starting a comment; a listed path is not reported.

This is a scanner, not a compiler: comments, strings (raw strings included),
character literals and preprocessor lines are blanked first, then braces are
matched and each block's head (the text since the previous ';', '{' or '}')
says what the block is.
"""
import argparse
import os
import re
import sys

EXTENSIONS = ('.cpp', '.hpp', '.h', '.cc')


def literal_end(text, i):
    """Index of the quote that closes the string or character literal whose
    opening quote is text[i] (len(text) when unterminated)."""
    j = i + 1
    while j < len(text) and text[j] != text[i]:
        j += 2 if text[j] == '\\' else 1
    return min(j, len(text))


def blank(text):
    """Returns text with comments, literals and preprocessor lines replaced by
    spaces, newlines kept, so that offsets and line numbers stay true."""
    out = list(text)
    i, n = 0, len(text)

    def wipe(a, b):
        for k in range(a, b):
            if out[k] != '\n':
                out[k] = ' '

    line_start = True
    while i < n:
        c = text[i]
        if c == '\n':
            line_start = True
            i += 1
            continue
        if line_start and c in ' \t':
            i += 1
            continue
        if line_start and c == '#':
            # A preprocessor line, with its backslash continuations.
            j = i
            while j < n and not (text[j] == '\n' and text[j - 1] != '\\'):
                j += 1
            wipe(i, j)
            i = j
            continue
        line_start = False
        if text.startswith('//', i):
            j = text.find('\n', i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            wipe(i, j)
            i = j
        elif c == '"':
            # A raw string: R"delim( ... )delim", perhaps with u8/u/U/L before.
            raw = re.search(r'(?<![\w])(?:u8|[uUL])?R$', text[max(0, i - 3):i])
            m = re.match(r'"([^()\\ ]{0,16})\(', text[i:i + 20]) if raw else None
            if m:
                close = ')' + m.group(1) + '"'
                j = text.find(close, i + len(m.group(0)))
                j = n if j < 0 else j + len(close)
                wipe(i + 1, j - 1)
                i = j
                continue
            j = literal_end(text, i)
            wipe(i + 1, j)
            i = j + 1
        elif c == "'":
            # A digit separator (1'000) or a character literal.
            k = i - 1
            while k >= 0 and (text[k].isalnum() or text[k] in '_.'):
                k -= 1
            if k + 1 < i and text[k + 1].isdigit():
                i += 1
                continue
            j = literal_end(text, i)
            wipe(i + 1, j)
            i = j + 1
        else:
            i += 1
    return ''.join(out)


def match_brace(s, i):
    """Index of the '}' that closes the '{' at s[i]."""
    depth = 0
    for k in range(i, len(s)):
        if s[k] == '{':
            depth += 1
        elif s[k] == '}':
            depth -= 1
            if depth == 0:
                return k
    return len(s) - 1


def top_level(head):
    """head with the contents of (), [] and <> of templates removed, keeping
    the brackets themselves, so that the shape of a declaration shows."""
    out, depth = [], 0
    for c in head:
        if c in '([':
            if depth == 0:
                out.append(c)
            depth += 1
        elif c in ')]':
            depth = max(0, depth - 1)
            if depth == 0:
                out.append(c)
        elif depth == 0:
            out.append(c)
    return ''.join(out)


OPERATOR = re.compile(r'\boperator\s*(\(\s*\)|\[\s*\]|<=>|->\*?|<<=?|>>=?|[-+*/%^&|~!=<>,]=?|&&|\|\||\+\+|--|\bnew\b|\bdelete\b|"\s*"\s*\w+|[\w:<> ]+?(?=\s*\())')
ACCESS = re.compile(r'\b(public|private|protected)\s*:(?!:)')
QUALIFIERS = re.compile(r'^(\s*(const|volatile|noexcept(\s*\(\))?|override|final|mutable|&&?|->[^{;]*|requires[^{;]*|\[\[[^\]]*\]\]))*\s*$')


def classify(head):
    """What a '{' opens, from the text before it: 'scope' (namespace or
    extern "C"), 'class', 'function', 'ctor-init' (a brace in a constructor's
    member initializer list or inside parentheses: part of the head) or 'data'."""
    h = ACCESS.split(head)[-1] if ACCESS.search(head) else head
    h = re.sub(r'\[\[[^\]]*\]\]', ' ', h)
    h = OPERATOR.sub('operator_', h)
    h = h.strip()
    if h.count('(') + h.count('[') > h.count(')') + h.count(']'):
        return 'ctor-init'  # a brace inside parentheses: part of the head
    if re.match(r'^(inline\s+)?namespace\b', h) or re.match(r'^extern\s*$', h):
        return 'scope'
    flat = top_level(re.sub(r'template\s*<[^;{}]*?>\s*(?=(class|struct|union|\w))', ' ', h, count=1))
    if re.search(r'\benum\b', flat):
        return 'data'
    if re.match(r'^(\w+\s+)*?(class|struct|union)\b', flat.strip()) and '(' not in flat:
        return 'class'
    if '(' not in flat:
        return 'data'
    # A lambda bound to a name at namespace or class scope.
    if re.search(r'=\s*\[[^\]]*\]\s*(\(\))?', flat) and re.search(r'\]\s*(\(\))?[^=]*$', flat):
        return 'function'
    if '=' in flat.replace('==', ''):
        return 'data'
    # Constructor: ') :' then the member initializers, whose braces come
    # before the body's.
    if re.search(r'\)\s*(noexcept(\s*\(\))?\s*)?:(?!:)', flat):
        return 'ctor-init' if re.search(r'[\w>]\s*$', flat) else 'function'
    tail = flat[flat.rfind(')') + 1:]
    if QUALIFIERS.match(tail):
        return 'function'
    return 'data'


def function_name(head):
    h = ACCESS.split(head)[-1] if ACCESS.search(head) else head
    h = re.sub(r'\[\[[^\]]*\]\]', ' ', h)
    lam = re.search(r'([\w:]+)\s*=\s*\[', top_level(h))
    if lam:
        return lam.group(1)
    m = re.search(r'(~?[\w:]*operator\s*(\(\s*\)|[^(\s]+)|~?[\w:]+(?:<[^()]*>)?)\s*\(', h)
    return ' '.join(m.group(1).split()) if m else '?'


def functions(text):
    """Yields (name, first_line, last_line) for each function in text."""
    s = blank(text)
    line_of = []
    line = 1
    for c in s:
        line_of.append(line)
        if c == '\n':
            line += 1

    def scan(begin, end):
        head_start = begin
        i = begin
        while i < end:
            c = s[i]
            if c in ';}':
                head_start = i + 1
            elif c == '{':
                head = s[head_start:i]
                kind = classify(head)
                close = match_brace(s, i)
                if kind == 'ctor-init':
                    i = close + 1
                    continue
                if kind == 'function':
                    first = head_start + len(head) - len(head.lstrip())
                    # Access specifiers are not part of the signature.
                    m = None
                    for m in ACCESS.finditer(head):
                        pass
                    if m:
                        first = head_start + m.end() + len(head[m.end():]) - len(head[m.end():].lstrip())
                    yield function_name(head), line_of[first], line_of[close]
                elif kind in ('scope', 'class'):
                    yield from scan(i + 1, close)
                i = close + 1
                head_start = i
                continue
            i += 1

    yield from scan(0, len(s))


def source_files(paths):
    for path in paths:
        if os.path.isdir(path):
            for root, dirs, files in os.walk(path):
                dirs.sort()
                for f in sorted(files):
                    if f.endswith(EXTENSIONS):
                        yield os.path.join(root, f)
        else:
            yield path


def read_exclusions(path):
    if not path:
        return []
    with open(path, encoding='utf-8') as f:
        return [ln.split('#', 1)[0].strip() for ln in f if ln.split('#', 1)[0].strip()]


def excluded(path, exclusions):
    p = os.path.normpath(path)
    for e in exclusions:
        if e.endswith('/') and (p + '/').startswith(e):
            return True
        if p == os.path.normpath(e):
            return True
    return False


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split('\n', 1)[0])
    ap.add_argument('--max', type=int, default=80, help='longest allowed function, in lines (default 80)')
    ap.add_argument('--exclude', help='file listing paths not to report')
    ap.add_argument('--all', action='store_true', help='list every function with its length')
    ap.add_argument('paths', nargs='+')
    args = ap.parse_args(argv)
    exclusions = read_exclusions(args.exclude)
    too_long = 0
    for path in source_files(args.paths):
        if excluded(path, exclusions):
            continue
        with open(path, encoding='utf-8', errors='replace') as f:
            text = f.read()
        for name, first, last in functions(text):
            length = last - first + 1
            if args.all:
                print(f'{path}:{first}: {name} is {length} lines')
            elif length > args.max:
                print(f'{path}:{first}: {name} is {length} lines (limit {args.max})')
                too_long += 1
    if too_long:
        print(f'{too_long} function(s) over {args.max} lines', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
