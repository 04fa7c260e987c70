"""Platforms: the twister description of each board, boards/<arch>/<board>/<board>.yaml."""

from dataclasses import dataclass, field
from pathlib import Path

from .config import ConfigError, load_validated


@dataclass
class Platform:
    identifier: str
    arch: str
    name: str = ""
    type: str = "native"
    toolchain: list = field(default_factory=list)
    ram: int = 0
    flash: int = 0
    supported: list = field(default_factory=list)
    default: bool = False
    timeout_multiplier: float = 1.0
    only_tags: list = field(default_factory=list)
    ignore_tags: list = field(default_factory=list)
    # `simulation:` entries, Zephyr's spelling: [{name, exec}]. The first one with an `exec`
    # names the program that runs the image (qemu-user for a board of another CPU).
    simulation: list = field(default_factory=list)
    path: Path | None = None

    @property
    def emulator(self) -> str | None:
        """The program the image runs under (`<exec> zephyr.exe <args>`), None for the host."""
        for sim in self.simulation:
            if sim.get("exec"):
                return sim["exec"]
        return None

    @classmethod
    def from_dict(cls, data: dict, path: Path | None = None) -> "Platform":
        testing = data.get("testing") or {}
        return cls(
            identifier=data["identifier"],
            arch=data["arch"],
            name=data.get("name", data["identifier"]),
            type=data.get("type", "native"),
            toolchain=list(data.get("toolchain") or []),
            ram=int(data.get("ram", 0) or 0),
            flash=int(data.get("flash", 0) or 0),
            supported=list(data.get("supported") or []),
            default=bool(testing.get("default", False)),
            timeout_multiplier=float(testing.get("timeout_multiplier", 1.0)),
            only_tags=list(testing.get("only_tags") or []),
            ignore_tags=list(testing.get("ignore_tags") or []),
            simulation=[dict(sim) for sim in data.get("simulation") or []],
            path=path,
        )


def load_platforms(board_roots: list[Path], display=lambda p: str(p)):
    """Read every boards/*/*/<board>.yaml under the board roots.

    Returns ({identifier: Platform}, [ConfigError]). A file whose name is not the name of its
    folder is not a board description (board.yml and friends) and is ignored.
    """
    platforms: dict[str, Platform] = {}
    errors: list[ConfigError] = []
    for root in board_roots:
        for path in sorted(Path(root).glob("*/*/*.yaml")):
            if path.stem != path.parent.name:
                continue
            data, errs = load_validated(path, display(path), "platform-schema.yaml")
            if errs:
                errors.extend(errs)
                continue
            plat = Platform.from_dict(data, path)
            if plat.identifier in platforms:
                other = display(platforms[plat.identifier].path)
                errors.append(
                    ConfigError(display(path), "identifier", f"duplicate platform {plat.identifier!r} (also {other})")
                )
                continue
            platforms[plat.identifier] = plat
    return platforms, errors
