"""include/shadermatrix/pack.h compiles as C99, C11 and C++17 with gcc 12 and clang 14, warnings as errors
(the strict set an engine may build with, beyond -Wall -Wextra -pedantic), in both of its modes: a file using
the declarations only, and the one defining SHADERMATRIX_PACK_IMPLEMENTATION; the two link and run."""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from .conftest import HEADER, INCLUDE, REPO, WARNINGS, compile_c, compiler
from .test_pack_h_checks import small_pack

pytestmark = pytest.mark.toolchain

STRICT = [*WARNINGS, "-O2", "-Wconversion", "-Wsign-conversion", "-Wshadow", "-Wcast-qual", "-Wformat=2",
          "-Wundef"]
STRICT_C = ["-Wstrict-prototypes", "-Wmissing-prototypes", "-Wold-style-definition"]

USER = r"""/* uses every declaration, as a file of an engine does */
#include "shadermatrix/pack.h"
#include <stdio.h>

#ifdef __cplusplus
extern "C" /* called from the implementation's file, which may be C */
#endif
int check_pack(const void *data, size_t size);
int check_pack(const void *data, size_t size) {
    smpack pack;
    smpack_entry e, f;
    size_t meta_length = 0;
    unsigned char sha[32];
    smpack_status st = smpack_open_memory(&pack, data, size);
    if (st != SMPACK_OK) {
        printf("%s %s\n", smpack_status_name(st), smpack_error(&pack));
        return 1;
    }
    smpack_sha256(data, size, sha);
    if (!smpack_meta(&pack, &meta_length) || meta_length == 0 || smpack_count(&pack) == 0) return 2;
    if (smpack_entry_at(&pack, 0, &e) != SMPACK_OK || smpack_find(&pack, e.permutation, e.stage, &f) != SMPACK_OK)
        return 3;
    if (f.data != e.data || smpack_find(&pack, "cccccccccccc", "frag", &f) != SMPACK_ERR_NOT_FOUND) return 4;
    smpack_close(&pack);
    return smpack_count(&pack) == 0 ? 0 : 5;
}
"""

IMPLEMENTATION = r"""#define SHADERMATRIX_PACK_IMPLEMENTATION
#include "shadermatrix/pack.h"
#include "shadermatrix/pack.h" /* a second inclusion defines nothing twice */
#include <stdio.h>

#ifdef __cplusplus
extern "C"
#endif
int check_pack(const void *data, size_t size);

int main(int argc, char **argv) {
    smpack pack;
    smpack_status st;
    int rc;
    if (argc != 2) return 9;
    st = smpack_open_file(&pack, argv[1]);
    if (st != SMPACK_OK) {
        printf("%s %s\n", smpack_status_name(st), smpack_error(&pack));
        return 1;
    }
    rc = check_pack(pack.data, pack.size);
    printf("%u entries, %d\n", (unsigned)smpack_count(&pack), rc);
    smpack_close(&pack);
    return rc;
}
"""

CONFIGS = {  # name: (compiler of the user file, of the implementation file, the standard flags of each)
    "gcc c99": ("gcc", "gcc", "-std=c99", "-std=c99"),
    "gcc c11": ("gcc", "gcc", "-std=c11", "-std=c11"),
    "clang-14 c99": ("clang-14", "clang-14", "-std=c99", "-std=c99"),
    "clang-14 c11": ("clang-14", "clang-14", "-std=c11", "-std=c11"),
    "g++ c++17": ("g++", "g++", "-std=c++17", "-std=c++17"),
    "clang++-14 c++17": ("clang++-14", "clang++-14", "-std=c++17", "-std=c++17"),
    "g++ c++17 user, gcc c11 implementation": ("g++", "gcc", "-std=c++17", "-std=c11"),
}


@pytest.mark.parametrize("config", list(CONFIGS))
def test_the_header_compiles_links_and_runs(config, tmp_path):
    user_cc, impl_cc, user_std, impl_std = CONFIGS[config]
    objects = []
    for name, cc, std, text in [("user", user_cc, user_std, USER), ("implementation", impl_cc, impl_std, IMPLEMENTATION)]:
        cpp = "++" in cc
        src = tmp_path / (name + (".cpp" if cpp else ".c"))
        src.write_text(text)
        obj = tmp_path / (name + ".o")
        compile_c([compiler(cc), std, *STRICT, *([] if cpp else STRICT_C), f"-I{INCLUDE}", "-c", str(src), "-o",
                   str(obj)], f"{config}: {name} file does not compile warning-free")
        objects.append(str(obj))
    exe = tmp_path / "check"
    compile_c([compiler(user_cc), *objects, "-o", str(exe)], f"{config}: does not link")
    pack = tmp_path / "x.smpack"
    pack.write_bytes(small_pack())
    r = subprocess.run([str(exe), str(pack)], capture_output=True, text=True, timeout=30)
    assert (r.returncode, r.stdout) == (0, "5 entries, 0\n"), r.stdout + r.stderr


def test_every_function_of_the_header_is_documented():
    text = HEADER.read_text()
    declarations = text.split("#ifdef __cplusplus\n}\n#endif\n#endif /* SHADERMATRIX_PACK_H */")[0]
    for name in ["smpack_open_memory", "smpack_open_file", "smpack_close", "smpack_error", "smpack_status_name",
                 "smpack_count", "smpack_entry_at", "smpack_find", "smpack_meta", "smpack_sha256"]:
        found = re.search(rf"\n(?:const )?\w+ +\*?{name}\(", declarations)
        assert found, f"{name} is not declared"
        assert declarations[:found.start()].rstrip().endswith("*/"), f"{name} has no comment above it"


def test_the_reference_pages_example_compiles(tmp_path):
    """docs/reference/pack-h.md's C example (the block that loads a module into vkCreateShaderModule), against
    the Vulkan headers of libvulkan-dev."""
    from tests.conftest import require
    require(Path("/usr/include/vulkan/vulkan.h").is_file(), "no Vulkan headers — run `make setup` (libvulkan-dev)")
    page = (REPO / "docs" / "reference" / "pack-h.md").read_text()
    [example] = [b for b in re.findall(r"```c\n(.*?)```", page, re.S) if "vkCreateShaderModule" in b]
    for cc, suffix, std in [("gcc", ".c", "-std=c11"), ("g++", ".cpp", "-std=c++17")]:
        src = tmp_path / ("example" + suffix)
        src.write_text(example)
        compile_c([compiler(cc), std, *STRICT, f"-I{INCLUDE}", "-c", str(src), "-o", str(tmp_path / "example.o")],
                  f"the example of docs/reference/pack-h.md does not compile with {cc}")


def test_a_missing_compiler_skips_and_fails_under_ci(monkeypatch):
    monkeypatch.setenv("PATH", "/nonexistent")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception, match="gcc not found .*CI=true"):
        compiler("gcc")
    monkeypatch.setenv("CI", "")
    with pytest.raises(pytest.skip.Exception, match="gcc not found"):
        compiler("gcc")
