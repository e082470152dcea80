#!/usr/bin/env python3
"""Functions of 100 lines or more in the workspace's source (tests and benches left out),
longest first: `scripts/fnlen.py [ROOT]`. A function is counted from its `fn` line to the
closing brace at its own indentation (rustfmt's layout)."""
import glob, re, sys

root = sys.argv[1] if len(sys.argv) > 1 else '.'
found = []
for f in glob.glob(root + '/crates/**/*.rs', recursive=True) + glob.glob(root + '/python/**/*.rs', recursive=True):
    if '/tests/' in f or '/benches/' in f:
        continue
    lines = open(f).read().split('\n')
    for i, line in enumerate(lines):
        m = re.match(r'^(\s*)(pub(\([a-z]+\))? )?(const )?(unsafe )?fn \w+', line)
        if not m:
            continue
        end = next((j for j in range(i + 1, len(lines)) if lines[j] == m.group(1) + '}'), None)
        if end is not None and end - i + 1 >= 100:
            found.append((end - i + 1, f, i + 1, line.strip()[:70]))
for n, f, at, text in sorted(found, reverse=True):
    print(f'{n:4} {f}:{at} {text}')
print(f'{len(found)} functions of 100 lines or more')
