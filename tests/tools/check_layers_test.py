#!/usr/bin/env python3
"""tools/check_layers.py on fixture trees: a tree that follows the layer map
passes, and each kind of wrong include fails it, naming the file and line."""

import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "tools" / "check_layers.py"

# A small tree in the repository's shape, every include allowed.
GOOD_TREE = {
    "runtime/include/mmvk/common/status.hpp": "",
    "runtime/include/mmvk/features/feature_schema.hpp": '#include "mmvk/common/status.hpp"\n',
    "runtime/include/mmvk/features/normalization.hpp": '#include "mmvk/features/feature_schema.hpp"\n',
    "runtime/include/mmvk/database/database.hpp": '#include "mmvk/features/normalization.hpp"\n',
    "runtime/include/mmvk/search/search.hpp": '#include "mmvk/database/database.hpp"\n',
    "runtime/include/mmvk/mmvk.hpp": '#include "mmvk/search/search.hpp"\n',
    "runtime/src/features/feature_schema.cpp": '#include "mmvk/features/feature_schema.hpp"\n',
    "runtime/src/features/normalization.cpp": '#include "mmvk/features/normalization.hpp"\n',
    "runtime/src/database/database.cpp": '#include "mmvk/database/database.hpp"\n#include "database/cost_bound.hpp"\n',
    "runtime/src/database/cost_bound.hpp": '#include "mmvk/database/database.hpp"\n',
    "runtime/src/search/search.cpp": '#include "mmvk/search/search.hpp"\n#include "database/cost_bound.hpp"\n',
    "runtime/vulkan/include/mmvk/vulkan/context.hpp": '#include "mmvk/common/status.hpp"\n',
    "runtime/vulkan/src/check.hpp": '#include "mmvk/vulkan/context.hpp"\n',
    "runtime/vulkan/src/context.cpp": '#include "check.hpp"\n#include "mmvk/search/search.hpp"\n',
    "host/cli/main.cpp": '#include "commands.hpp"\n#include "mmvk/search/search.hpp"\n#include "mmvk/vulkan/context.hpp"\n',
    "host/cli/commands.hpp": "",
    "tests/cpu/search_test.cpp": '#include "support/data.hpp"\n#include "mmvk/search/search.hpp"\n',
    "tests/cpu/start_here_test.cpp": '#include "mmvk/mmvk.hpp"\n',
    "tests/support/data.hpp": '#include "mmvk/database/database.hpp"\n',
}


def run_check(tree):
    with tempfile.TemporaryDirectory() as root:
        for rel, text in tree.items():
            path = Path(root) / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
        result = subprocess.run([sys.executable, str(SCRIPT), "--root", root], capture_output=True, text=True)
        return result.returncode, result.stderr


def with_file(rel, text):
    tree = dict(GOOD_TREE)
    tree[rel] = text
    return tree


class CheckLayersTest(unittest.TestCase):
    def assert_fails(self, tree, *words):
        code, errors = run_check(tree)
        self.assertEqual(code, 1, errors)
        for word in words:
            self.assertIn(word, errors)

    def test_a_tree_that_follows_the_map_passes(self):
        code, errors = run_check(GOOD_TREE)
        self.assertEqual(code, 0, errors)

    def test_a_public_header_that_includes_a_higher_layer_fails(self):
        # The case: normalization.hpp (features) including database.hpp.
        self.assert_fails(with_file("runtime/include/mmvk/features/normalization.hpp",
                                    '#include "mmvk/features/feature_schema.hpp"\n#include "mmvk/database/database.hpp"\n'),
                          "runtime/include/mmvk/features/normalization.hpp:2", "goes up a layer: features includes database")

    def test_a_source_that_includes_a_higher_layers_private_header_fails(self):
        tree = with_file("runtime/src/search/cost_bound.hpp", "")
        tree["runtime/src/database/database.cpp"] = '#include "mmvk/database/database.hpp"\n#include "search/cost_bound.hpp"\n'
        self.assert_fails(tree, "runtime/src/database/database.cpp:2", "database includes search")

    def test_the_runtime_including_the_vulkan_target_fails(self):
        self.assert_fails(with_file("runtime/src/search/search.cpp", '#include "mmvk/vulkan/context.hpp"\n'),
                          "runtime/src/search/search.cpp:1", "includes mmvk::vulkan")

    def test_a_host_including_a_private_header_fails(self):
        self.assert_fails(with_file("host/cli/main.cpp", '#include "database/cost_bound.hpp"\n'),
                          "host/cli/main.cpp:1", "private header of mmvk::runtime")
        self.assert_fails(with_file("bench/vulkan_bench.cpp", '#include "check.hpp"\n'),
                          "bench/vulkan_bench.cpp:1", "private header of mmvk::vulkan")

    def test_an_include_by_relative_path_fails(self):
        self.assert_fails(with_file("tests/cpu/cost_test.cpp", '#include "../../runtime/src/database/cost_bound.hpp"\n'),
                          "tests/cpu/cost_test.cpp:1", "relative path")

    def test_a_public_header_outside_a_layer_folder_fails(self):
        self.assert_fails(with_file("runtime/include/mmvk/mystery.hpp", ""), "mystery.hpp: not in a layer folder")
        self.assert_fails(with_file("runtime/include/mmvk/misc/mystery.hpp", ""), "misc/mystery.hpp: not in a layer")

    def test_the_runtime_including_the_start_here_header_fails(self):
        self.assert_fails(with_file("runtime/src/search/search.cpp", '#include "mmvk/mmvk.hpp"\n'),
                          "runtime/src/search/search.cpp:1", "not mmvk/mmvk.hpp")


if __name__ == "__main__":
    unittest.main()
