#!/usr/bin/env python3
"""Tests tools/check_function_length.py on the fixtures beside this file:
the long function is reported (exit 1), every short one passes, and the
scanner finds each function of the tricky fixture, no more and no less."""
import os
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, '..', '..', 'tools', 'check_function_length.py')
FIXTURES = os.path.join(HERE, 'function_length')


def check(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class CheckFunctionLength(unittest.TestCase):
    def test_long_function_fails(self):
        r = check(os.path.join(FIXTURES, 'long.cpp'))
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        lines = r.stdout.splitlines()
        self.assertEqual(len(lines), 1, r.stdout)
        self.assertIn('long.cpp:6: long_function is 84 lines (limit 80)', lines[0])

    def test_short_functions_pass(self):
        r = check(os.path.join(FIXTURES, 'short.cpp'))
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertEqual(r.stdout, '')

    def test_limit_is_an_option(self):
        self.assertEqual(check('--max', '84', os.path.join(FIXTURES, 'long.cpp')).returncode, 0)
        self.assertEqual(check('--max', '8', os.path.join(FIXTURES, 'short.cpp')).returncode, 1)

    def test_finds_every_function(self):
        r = check('--all', os.path.join(FIXTURES, 'short.cpp'))
        self.assertEqual(r.returncode, 0, r.stderr)
        found = [line.split(': ', 1)[1] for line in r.stdout.splitlines()]
        self.assertEqual(found, [
            'namespace_lambda is 3 lines',   # a lambda bound at namespace scope
            'Widget is 4 lines',             # braces in the initializer list
            'Widget is 1 lines',             # a brace inside parentheses
            'operator= is 4 lines',
            'sum is 1 lines',
            'twice is 1 lines',              # a nested class's member
            'multi_line_signature is 9 lines',  # its lambda counts toward it
        ])

    def test_exclusion_list(self):
        listed = os.path.join(os.environ.get('TMPDIR', '/tmp'), f'fnlen-exclude-{os.getpid()}.txt')
        with open(listed, 'w', encoding='utf-8') as f:
            f.write('# comment\n' + os.path.normpath(os.path.join(FIXTURES, 'long.cpp')) + '\n')
        try:
            self.assertEqual(check('--exclude', listed, FIXTURES).returncode, 0)
        finally:
            os.unlink(listed)
        self.assertEqual(check(FIXTURES).returncode, 1)


if __name__ == '__main__':
    unittest.main()
