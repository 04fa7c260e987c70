"""Test instances (one scenario on one platform) and their test cases."""

from dataclasses import dataclass, field
from pathlib import Path

from . import statuses as st
from .boards import Platform
from .config import ConfigError, Scenario


@dataclass
class TestCase:
    __test__ = False  # not a pytest test class

    identifier: str  # <scenario>.<suite>.<case> for ztest
    status: str | None = None
    reason: str | None = None
    duration: float = 0.0

    def to_dict(self) -> dict:
        d = {"identifier": self.identifier, "status": self.status, "duration": self.duration}
        if self.reason:
            d["reason"] = self.reason
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "TestCase":
        return cls(d["identifier"], d.get("status"), d.get("reason"), float(d.get("duration", 0.0)))


@dataclass
class TestInstance:
    __test__ = False

    scenario: Scenario | None
    platform: Platform | None
    build_dir: Path | None = None
    status: str | None = None
    reason: str | None = None
    testcases: list[TestCase] = field(default_factory=list)
    build_time: float = 0.0
    execution_time: float = 0.0
    retries: int = 0
    build_only: bool = False  # built, never run (-b or build_only: true)
    log: str | None = None  # the failing log's text, for twister.json
    log_file: Path | None = None  # build.log or handler.log of a failure (for -i)
    recording: list = field(default_factory=list)
    config_error: ConfigError | None = None  # for the "error" entry of a bad YAML file

    @classmethod
    def for_config_errors(cls, errors: list[ConfigError]) -> "TestInstance":
        """One "error" entry for a file: the first problem as reason, all of them as log."""
        reason = str(errors[0])
        if len(errors) > 1:
            reason += f" (and {len(errors) - 1} more)"
        return cls(None, None, status=st.ERROR, reason=reason, config_error=errors[0],
                   log="\n".join(str(e) for e in errors) + "\n")

    @property
    def name(self) -> str:
        if self.scenario is None:
            return self.config_error.file
        return f"{self.platform.identifier}/{self.scenario.relpath}/{self.scenario.id}"

    @property
    def scenario_id(self) -> str:
        return self.scenario.id if self.scenario else self.config_error.file

    @property
    def platform_id(self) -> str:
        return self.platform.identifier if self.platform else ""

    @property
    def counts_cases(self) -> bool:
        """Whether the final count line counts this instance's test cases (not the instance).

        Test cases for ztest and pytest scenarios that are (or would have been) run; one per
        instance for console scenarios, build-only instances and configuration errors.
        """
        if self.scenario is None or self.build_only:
            return False
        return self.scenario.harness in ("ztest", "pytest")

    def init_cases(self) -> None:
        """The expected cases, known before anything runs."""
        if self.scenario is None:
            return
        if self.scenario.harness == "ztest":
            self.testcases = [TestCase(f"{self.scenario.id}.{c}") for c in self.scenario.cases]
        elif self.scenario.harness == "console":
            self.testcases = [TestCase(self.scenario.id)]
        else:
            self.testcases = []

    def set_status(self, status: str, reason: str | None = None) -> None:
        self.status = status
        self.reason = reason

    def fill_cases(self, status: str, reason: str | None = None) -> None:
        """Give every case that has no final result yet `status` (the instance ended)."""
        for tc in self.testcases:
            if tc.status in (None, st.STARTED):
                tc.status = status
                tc.reason = reason
