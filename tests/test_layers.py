"""The package's layers: a module imports only from its own layer and the layers below it, and no modules import
each other round a loop. Every import statement counts, those inside functions too. The order is written once,
in `LAYERS`; docs/extending.md ("Layers") says what each layer is for."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("lerobot_tavis", "lerobot_env_tavis")

# Bottom to top. A name stands for that module and everything under it; the longest name that matches places a
# module. A new module joins the layer of what it is for, below every module that imports it.
LAYERS = (
    ("shared helpers", ("lerobot_tavis.errors", "lerobot_tavis.atomic", "lerobot_tavis.process",
                        "lerobot_tavis.tempdir", "lerobot_tavis.importpath", "lerobot_tavis.canonical",
                        "lerobot_tavis.checks", "lerobot_tavis.readers", "lerobot_tavis.locking",
                        "lerobot_tavis.staging", "lerobot_tavis.workers", "lerobot_tavis.media",
                        "lerobot_tavis.overlay", "lerobot_tavis.cli_options", "lerobot_tavis.lerobot_cli_errors")),
    ("simulation", ("lerobot_tavis.envs",)),
    ("demonstrators and metrics", ("lerobot_tavis.experts", "lerobot_tavis.metrics", "lerobot_tavis.registry")),
    ("datasets", ("lerobot_tavis.dataset_tools",)),
    ("policies", ("lerobot_tavis.policies",)),
    ("training presets and sharing", ("lerobot_tavis.policy_configs", "lerobot_tavis.policy_hub")),
    ("evaluation", ("lerobot_tavis.eval",)),
    ("commands and plugin", ("lerobot_tavis.demo", "lerobot_tavis.gallery", "lerobot_tavis.viewer",
                             "lerobot_tavis.teleop", "lerobot_tavis.cli", "lerobot_tavis", "lerobot_env_tavis")),
)


def module_files() -> dict[str, Path]:
    """Every module of the packages by dotted name (a package by its `__init__.py`)."""
    modules = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return modules


def imports(path: Path, modules: dict[str, Path]) -> set[str]:
    """The modules of `modules` that the file imports (`from package import module` names the module)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            assert node.level == 0, f"{path}: a relative import; the layer check reads absolute ones only"
            found |= {f"{node.module}.{alias.name}" if f"{node.module}.{alias.name}" in modules else node.module
                      for alias in node.names}
    return {name for name in found if name in modules}


def layer_of(module: str) -> int:
    """The index in LAYERS of the layer `module` belongs to (by the longest matching name)."""
    matches = [(len(name), index) for index, (_, names) in enumerate(LAYERS) for name in names
               if module == name or module.startswith(name + ".")]
    assert matches, f"{module} is in no layer: add it to LAYERS in {__file__}"
    return max(matches)[1]


def import_graph() -> dict[str, set[str]]:
    """Each module of the packages and the modules of the packages it imports."""
    modules = module_files()
    return {module: imports(path, modules) - {module} for module, path in modules.items()}


def upward_imports(graph: dict[str, set[str]]) -> list[str]:
    """Every import of `graph` from a module to one of a higher layer, as a sentence."""
    return [f"{module} ({LAYERS[layer_of(module)][0]}) imports {target} ({LAYERS[layer_of(target)][0]})"
            for module, targets in sorted(graph.items()) for target in sorted(targets)
            if layer_of(target) > layer_of(module)]


def loops(graph: dict[str, set[str]]) -> list[str]:
    """The import loops of `graph`, each as "a -> b -> a" from the first module where the search met it."""
    found, done = [], set()

    def visit(module: str, path: list[str]) -> None:
        if module in path:
            found.append(" -> ".join([*path[path.index(module):], module]))
        elif module not in done:
            for target in sorted(graph.get(module, ())):
                visit(target, [*path, module])
            done.add(module)

    for module in sorted(graph):
        visit(module, [])
    return found


def test_every_module_imports_only_from_its_layer_and_those_below():
    assert upward_imports(import_graph()) == []


def test_no_modules_import_each_other_round_a_loop():
    assert loops(import_graph()) == []


def test_the_checks_find_an_upward_import_inside_a_function_and_a_loop(tmp_path):
    source = tmp_path / "env.py"
    source.write_text("import numpy\n\n\ndef render():\n    from lerobot_tavis.eval import report\n")
    modules = {"lerobot_tavis.envs.env": source, "lerobot_tavis.eval.report": source}
    graph = {"lerobot_tavis.envs.env": imports(source, modules),
             "lerobot_tavis.eval.report": {"lerobot_tavis.eval.annotate"},
             "lerobot_tavis.eval.annotate": {"lerobot_tavis.eval.report"}}
    assert upward_imports(graph) == ["lerobot_tavis.envs.env (simulation) imports lerobot_tavis.eval.report "
                                     "(evaluation)"]
    assert loops(graph) == ["lerobot_tavis.eval.report -> lerobot_tavis.eval.annotate -> lerobot_tavis.eval.report"]


def test_the_docs_table_of_layers_lists_these_layers_and_modules():
    """docs/extending.md shows the layers as a table; its rows are LAYERS, in order ("the package itself" is
    `lerobot_tavis`, a name without package is under `lerobot_tavis/`)."""
    text = (ROOT / "docs" / "extending.md").read_text()
    table = text[text.index("| layer | modules"):].split("\n\n")[0].splitlines()[2:]
    rows = []
    for row in table:
        layer, modules = (cell.strip() for cell in row.strip("|").split("|")[:2])
        names = [name.rstrip("/") for name in modules.split("`")[1::2]]
        names = [name if name.startswith("lerobot_env_tavis") else f"lerobot_tavis.{name}" for name in names]
        rows.append((layer, tuple(sorted(names + ["lerobot_tavis"] * ("the package itself" in modules)))))
    assert rows == [(layer, tuple(sorted(names))) for layer, names in LAYERS]
