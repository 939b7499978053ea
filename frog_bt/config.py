"""Site configuration: POIs, time-of-day variants, tour order, timeouts, thresholds, links.

Loaded from ``config/site.yaml`` (or ``--config FILE``) and validated up front;
an error names the file, the path inside it and what was expected::

    config/site.yaml: tour.stops[2].poi: unknown POI 'POI9' (known: END, POI0, ...)
"""

from __future__ import annotations

import hashlib
import ipaddress
import math
import os
from datetime import time as dtime
from pathlib import Path
from typing import Annotated, Any, Literal
from urllib.parse import urlsplit

# pydantic looks for plugins in every installed distribution's entry points when it builds
# the first model (a tenth of a second at start-up); frog-bt has none. An explicit setting
# in the environment wins.
os.environ.setdefault("PYDANTIC_DISABLE_PLUGINS", "__all__")

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    field_validator,
    model_validator,
)

from frog_bt import resources
from frog_bt.errors import ConfigError, UsageError
from frog_bt.model.ros import Pose
from frog_bt.model.tours import TourPlan
from frog_bt.model.wire import (
    DEFAULT_FRONTEND,
    DEFAULT_LISTEN,
    DEFAULT_ROSBRIDGE_URL,
    INPUTS,
    OUTPUTS,
)
from frog_bt.text import inert, is_inert
from frog_bt.yamlfile import PathError, load_yaml, validate

DEFAULT_CONFIG = resources.site_dir() / resources.SITE_FILE

Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Finite = Annotated[float, Field(allow_inf_nan=False)]


def _plain_text(value: str) -> str:
    if len(value) > 200 or not is_inert(value):
        raise ValueError(
            "expected a line of plain text of at most 200 characters, without control "
            f"characters, got {inert(value, 40)!r}"
        )
    return value


# Words staff or visitors read (a stop's name, a zone, a spot): a line of plain text, no
# control or format characters (frog_bt.text), at most 200 characters
Text = Annotated[str, AfterValidator(_plain_text)]

WAYPOINT_TOLERANCE = 1e-3  # metres and quaternion units: a goal names a POI within it


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Poi(_Model):
    x: Finite
    y: Finite
    z: Finite
    w: Finite
    name: Text = ""
    # the name in a language staff may read (es: Patio de la Montería), used when it is
    # the site's `language`; `name` otherwise
    names: dict[Literal["en", "es"], Text] = {}
    note: Text = ""

    @model_validator(mode="after")
    def _unit_quaternion(self) -> Poi:
        if not math.isclose(math.hypot(self.z, self.w), 1.0, abs_tol=0.02):
            raise ValueError(f"orientation z={self.z}, w={self.w} is not a unit quaternion")
        return self


class Variant(_Model):
    """``waypoint`` is used while local time <= ``until`` (the last variant has no ``until``)."""

    waypoint: str
    until: dtime | None = None

    @field_validator("until", mode="before")
    @classmethod
    def _parse_time(cls, value: Any) -> Any:
        if isinstance(value, int) and not isinstance(value, bool):
            # YAML 1.1 reads 13:00 as the sexagesimal integer 780.
            return dtime(value // 60, value % 60)
        return value


class Stop(_Model):
    """One stop of the tour, in order."""

    poi: str
    content: bool = True
    face_stream: bool = False
    projector: bool = False
    check_follower: bool = True
    content_timeout: Positive | None = None


class Tour(_Model):
    dock: str = "SHOP"
    recruit_at: str = "POI0"
    stops: list[Stop]


class Timeouts(_Model):
    navigation: Positive = 600.0
    approach: Positive = 120.0
    undock: Positive = 60.0
    dock: Positive = 120.0
    introduction: Positive = 300.0
    answer: Positive = 120.0
    content: Positive = 600.0


class Navigation(_Model):
    attempts: int = Field(default=3, ge=1)
    # metres: an "arrived" is believed only this near its goal (by /FROG_pose), and
    # `dock` is sent only this near the dock's waypoint
    tolerance: Positive = 2.0
    # seconds: an arrival heard before a pose shows it is believed if one does this soon
    pose_grace: NonNegative = 2.0


class DockingCfg(_Model):
    attempts: int = Field(default=3, ge=1)  # tries of a dock or an undock before giving up


class Recruit(_Model):
    facing_min: Finite = 135.0
    facing_max: Finite = 225.0
    detection_max_age: Positive = 1.0
    # seconds a person whose approach failed (or was rejected) is not sought again:
    # the seed's "try to find new participant"
    retry_after: NonNegative = 60.0
    approach_interval: NonNegative = 5.0  # seconds at least between two /ApproachPeopleFar


class Follow(_Model):
    radius: Positive = 4.0
    grace: NonNegative = 10.0


class EngagementCfg(_Model):
    near: Positive = 2.0  # metres: farther faces are not stored
    window: Positive = 2.0  # seconds per engagement meter update
    edge: Annotated[float, Field(gt=0, le=0.5)] = 0.15  # first and last fraction voting
    on_tie: bool = False  # a tied vote tells more?
    no_data: bool = False  # no face data at all tells more?


class ProjectorCfg(_Model):
    warmup: Positive = 20.0  # seconds the projector needs to warm up
    margin: NonNegative = 5.0  # seconds of safety on top of the warm-up
    radius: Positive = 15.0  # metres: switch on inside this radius of the POI anyway
    speed_window: Positive = 5.0  # seconds of poses for the recent speed


class Circle(_Model):
    x: Finite
    y: Finite
    r: Positive


class ZoneShape(_Model):
    """A circle or a polygon (at least three ``[x, y]`` points), map frame."""

    circle: Circle | None = None
    polygon: list[tuple[Finite, Finite]] | None = None

    @model_validator(mode="after")
    def _one_shape(self) -> ZoneShape:
        if (self.circle is None) == (self.polygon is None):
            raise ValueError("expected exactly one of circle: {x, y, r} or polygon: [[x, y], ...]")
        if self.polygon is not None and len(self.polygon) < 3:
            raise PathError(("polygon",), "expected at least three points")
        return self


class VolumeZone(ZoneShape):
    name: Text
    percent: int = Field(ge=0, le=100)


class Volume(_Model):
    default: int = Field(default=100, ge=0, le=100)
    hysteresis: NonNegative = 1.0  # metres outside a zone before leaving it
    zones: list[VolumeZone] = []


class SpecialSpot(ZoneShape):
    spot: Text


class Zones(_Model):
    arrival: dict[str, Positive] = {"default": 5.0}  # metres around a POI; per POI or default
    volume: Volume = Volume()
    special: list[SpecialSpot] = []

    def arrival_radius(self, poi: str) -> float:
        return self.arrival.get(poi, self.arrival.get("default", 5.0))


class Safety(_Model):
    battery_low: Annotated[float, Field(ge=0, le=100)] = 20.0  # percent: abort the tour below
    battery_resume: Annotated[float, Field(ge=0, le=100)] = 30.0  # percent: start a tour from
    diagnostics_max_age: Positive = 5.0  # seconds: older /diagnostic is stale (not acted on)
    pose_max_age: Positive = 2.0  # seconds: older /FROG_pose is stale
    people_max_age: Positive = 2.0  # seconds: older /PeopleUPO is stale
    face_silence: Positive = 3.0  # seconds without face data while the stream is on: say so

    @model_validator(mode="after")
    def _resume_above_low(self) -> Safety:
        if self.battery_resume < self.battery_low:
            raise PathError(
                ("battery_resume",),
                f"expected at least battery_low ({self.battery_low:g}): a tour would start "
                "with a battery it aborts at",
            )
        return self


class Checkpoint(_Model):
    confirm: Positive = 3.0  # seconds to wait for /docking/state before resuming a tour
    max_age: Positive = 900.0  # wall seconds: an older checkpoint is not resumed


class OperatorCfg(_Model):
    pause_max: Positive = 300.0  # seconds an operator's pause may last; then the tour ends


def _http_url_problem(url: str) -> str | None:
    try:
        parts = urlsplit(url)
        parts.port  # noqa: B018 - a port that is not a number raises here
    except ValueError as exc:
        return f"expected an http:// or https:// URL ({exc})"
    if parts.scheme not in ("http", "https") or not parts.hostname:
        return "expected an http:// or https:// URL"
    return None


WebhookFormat = Literal["json", "ntfy", "alertmanager"]


class Webhook(_Model):
    """One destination of alert changes: ``url`` and the ``format`` it understands. A plain
    URL string in ``alerts.webhooks`` means ``{url: URL, format: json}``.

    * ``json``: the generic body, POSTed to ``url``;
    * ``ntfy``: ``url`` is the topic's URL (``https://ntfy.sh/TOPIC``); ntfy's JSON
      publish is POSTed to the server's root with ``topic`` = the last path segment;
    * ``alertmanager``: ``url`` is Alertmanager's base URL; ``POST {url}/api/v2/alerts``.
    """

    url: str
    format: WebhookFormat = "json"

    @model_validator(mode="before")
    @classmethod
    def _plain_url(cls, data: Any) -> Any:
        return {"url": data} if isinstance(data, str) else data

    @model_validator(mode="after")
    def _check(self) -> Webhook:
        problem = _http_url_problem(self.url)
        if problem:
            # the URL itself is not repeated: it may carry a password or a key
            raise ValueError(problem)
        if self.format == "ntfy" and not urlsplit(self.url).path.strip("/"):
            raise ValueError("an ntfy URL names its topic: https://HOST/TOPIC")
        return self


def _string_or_object(schema: dict[str, Any]) -> None:
    # a plain URL string is accepted too (json): the schema says so
    schema["items"] = {"anyOf": [{"type": "string", "format": "uri"}, schema["items"]]}


class AlertsCfg(_Model):
    battery_below: Annotated[float, Field(ge=0, le=100)] = 25.0  # percent: ask for help below
    rosbridge_down_after: Positive = 60.0  # seconds without the robot before an alert
    frontend_silent_after: Positive = 60.0  # seconds of a silent front end before an alert
    no_visitor_after: Positive = 900.0  # seconds of searching for a visitor before an alert
    # where each alert change goes: a URL (the generic JSON) or {url, format: json|ntfy|
    # alertmanager}
    webhooks: Annotated[list[Webhook], Field(json_schema_extra=_string_or_object)] = []
    webhook_timeout: Positive = 5.0  # seconds one POST may take
    webhook_attempts: Annotated[int, Field(ge=1, le=20)] = 5  # tries per alert and URL
    webhook_backoff: Positive = 1.0  # seconds before the 2nd try, doubling after each
    robot: Annotated[str, Field(pattern=r"^[A-Za-z0-9_.-]{1,64}$")] = "frog"  # in keys, labels
    console_url: str = ""  # the console as phones reach it: links in notifications ("": none)
    escalate_every: Positive = 600.0  # seconds: an unacknowledged alert is told again
    escalate_max: Annotated[int, Field(ge=0, le=100)] = 6  # ... at most this many times
    ack_link_ttl: Positive = 86400.0  # seconds an acknowledgement link stays valid (wall)

    @field_validator("console_url")
    @classmethod
    def _console_url(cls, url: str) -> str:
        if url:
            problem = _http_url_problem(url)
            if problem:
                raise ValueError(problem)
            parts = urlsplit(url)
            if parts.username or parts.password or parts.query or parts.fragment:
                raise ValueError(
                    "expected the console's address alone (no user, password, query or fragment)"
                )
        return url.rstrip("/")


class ConsoleCfg(_Model):
    commands_per_second: Positive = 2.0  # more from one client: 429 (10 at once)
    max_body: Annotated[int, Field(ge=64, le=1_000_000)] = 4096  # bytes of a request body
    push_every: Positive = 0.3  # seconds between pushed states (at once on a new phase)
    # reverse proxies (addresses or networks) whose X-Forwarded-For names the client
    trusted_proxies: list[str] = []

    @field_validator("trusted_proxies")
    @classmethod
    def _networks(cls, values: list[str]) -> list[str]:
        out = []
        for value in values:
            try:
                out.append(str(ipaddress.ip_network(value.strip(), strict=False)))
            except ValueError:
                raise ValueError(
                    f"expected IP addresses or networks (127.0.0.1, 10.0.0.0/8), got {value!r}"
                ) from None
        return out


def _local_times(values: Any) -> Any:
    """``["14:00", "20:00"]`` as times of day, in order, each once; YAML 1.1 reads an
    unquoted 14:00 as the sexagesimal integer 840, which is taken as 14:00 too."""
    if not isinstance(values, list):
        raise ValueError('expected a list of local times, e.g. ["14:00", "20:00"]')
    out: list[dtime] = []
    for i, value in enumerate(values):
        if isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 24 * 60:
            at = dtime(value // 60, value % 60)
        elif isinstance(value, str) and len(value) <= 5 and value.count(":") == 1:
            hours, _, minutes = value.partition(":")
            if not (hours.isdigit() and minutes.isdigit() and len(minutes) == 2):
                raise PathError((i,), f'expected a local time HH:MM (e.g. "14:00"), got {value!r}')
            if int(hours) > 23 or int(minutes) > 59:
                raise PathError((i,), f"expected a time of day from 00:00 to 23:59, got {value!r}")
            at = dtime(int(hours), int(minutes))
        else:
            shown = inert(str(value), 40)
            raise PathError((i,), f'expected a local time HH:MM (e.g. "14:00"), got {shown!r}')
        if at in out:
            raise PathError((i,), f"{at:%H:%M} is given twice")
        out.append(at)
    return sorted(out)


class StaffCfg(_Model):
    """The people who run the robot by shifts (the console)."""

    # local times (the site's, Europe/Madrid) at which the console composes a handover for
    # the next shift and sends it to the alerts' webhooks (json, ntfy); [] for none
    handover: Annotated[
        list[dtime],
        BeforeValidator(_local_times),
        Field(json_schema_extra={"items": {"type": "string", "pattern": r"^\d{1,2}:\d{2}$"}}),
    ] = []
    # seconds a pairing link (frog-bt ctl pair NAME, the page's QR code) stays valid
    pairing_ttl: Annotated[float, Field(gt=0, le=3600, allow_inf_nan=False)] = 300.0
    # where paired devices are kept (0600); default: beside the console's token file
    # (<token file>.devices); under systemd the token's directory is read-only: name one
    # in the service's state directory
    devices_file: str | None = None


class Recording(_Model):
    max_bytes: Annotated[int, Field(gt=0)] = 20_000_000_000  # --record DIR: disk budget


class Links(_Model):
    rosbridge: str = DEFAULT_ROSBRIDGE_URL
    frontend: str = "{}:{}".format(*DEFAULT_FRONTEND)
    listen: str = "{}:{}".format(*DEFAULT_LISTEN)
    secret_env: str = "FROG_ROSBRIDGE_SECRET"
    secret_file: str | None = None

    @field_validator("rosbridge")
    @classmethod
    def _ws_url(cls, value: str) -> str:
        problem = ws_url_problem(value)
        if problem:
            raise ValueError(problem)
        return value

    @field_validator("frontend", "listen")
    @classmethod
    def _hostport(cls, value: str) -> str:
        if hostport_problem(value):
            raise ValueError(f"expected HOST:PORT (e.g. 127.0.0.1:5005), got {value!r}")
        return value


class Executive(_Model):
    tick_hz: Positive = 10.0


class RunCfg(_Model):
    """``frog-bt run`` options kept in the site configuration (``run:``): the command line
    wins over ``FROG_BT_<OPTION>`` in the environment, which wins over these."""

    rosbridge: str | None = None
    frontend: str | None = None
    listen: str | None = None
    sim_time: bool | None = None
    record: str | None = None
    rerun: str | None = None
    checkpoint: str | None = None
    once: bool | None = None
    fresh: bool | None = None
    watch: bool | None = None
    quiet: bool | None = None
    console: str | None = None
    console_token_file: str | None = None
    log_format: Literal["text", "json"] | None = None


class Site(_Model):
    language: Literal["en", "es"] = "en"  # what staff read: the console, alerts, webhooks, ctl
    pois: dict[str, Poi]
    variants: dict[str, list[Variant]] = {}
    tour: Tour
    timeouts: Timeouts = Timeouts()
    navigation: Navigation = Navigation()
    docking: DockingCfg = DockingCfg()
    recruit: Recruit = Recruit()
    follow: Follow = Follow()
    links: Links = Links()
    executive: Executive = Executive()
    engagement: EngagementCfg = EngagementCfg()
    projector: ProjectorCfg = ProjectorCfg()
    zones: Zones = Zones()
    safety: Safety = Safety()
    checkpoint: Checkpoint = Checkpoint()
    recording: Recording = Recording()
    operator: OperatorCfg = OperatorCfg()
    run: RunCfg = RunCfg()
    alerts: AlertsCfg = AlertsCfg()
    console: ConsoleCfg = ConsoleCfg()
    staff: StaffCfg = StaffCfg()
    topics: dict[Literal[tuple(INPUTS) + tuple(OUTPUTS)], str] = {}  # type: ignore[valid-type]

    def name(self, poi: str) -> str:
        """A stop or waypoint by the name staff know it by, in the site's language (POI2
        or POI2a: Patio de la Montería, or Hunting Courtyard); the code itself when the
        site names neither."""
        found = self.pois.get(poi)
        if found is None and self.variants.get(poi):
            found = self.pois.get(self.variants[poi][0].waypoint)
        if found is None:
            return poi
        return found.names.get(self.language) or found.name or poi

    @model_validator(mode="after")
    def _cross_check(self) -> Site:
        known = sorted(self.pois)
        for name, variants in self.variants.items():
            if not variants:
                raise _at(("variants", name), "expected at least one variant")
            for i, v in enumerate(variants):
                if v.waypoint not in self.pois:
                    raise _at(("variants", name, i, "waypoint"), _unknown(v.waypoint, known))
                last = i == len(variants) - 1
                if (v.until is None) != last:
                    raise _at(
                        ("variants", name, i, "until"),
                        "every variant but the last needs 'until'; the last has none",
                    )
        for key in ("dock", "recruit_at"):
            if getattr(self.tour, key) not in self.pois:
                raise _at(("tour", key), _unknown(getattr(self.tour, key), known))
        for key in self.zones.arrival:
            if key != "default" and key not in self.pois and key not in self.variants:
                raise _at(("zones", "arrival", key), _unknown(key, known))
        for i, stop in enumerate(self.tour.stops):
            if stop.poi not in self.pois and stop.poi not in self.variants:
                raise _at(
                    ("tour", "stops", i, "poi"),
                    _unknown(stop.poi, sorted({*self.pois, *self.variants})),
                )
        return self

    # ------------------------------------------------------------ queries

    def waypoint_for(self, poi: str, local: dtime) -> str:
        """The waypoint (POI table id) for logical ``poi`` at local time of day ``local``."""
        for variant in self.variants.get(poi, ()):
            if variant.until is None or local <= variant.until:
                return variant.waypoint
        return poi

    def waypoint_of(self, pose: Pose) -> str:
        """The POI a goal's pose names (position and orientation within
        :data:`WAYPOINT_TOLERANCE`), or its position as ``(x, y)`` when none does: the one
        waypoint match (summary, replay, report)."""
        for name, poi in self.pois.items():
            near = (
                abs(poi.x - pose.x),
                abs(poi.y - pose.y),
                abs(poi.z - pose.qz),
                abs(poi.w - pose.qw),
            )
            if max(near) < WAYPOINT_TOLERANCE:
                return name
        return f"({pose.x:.1f}, {pose.y:.1f})"

    def topic(self, role: str) -> str:
        default = INPUTS.get(role) or OUTPUTS[role]
        return self.topics.get(role, default.name)

    def timeout(self, name: str) -> float:
        """The ``timeouts`` entry ``name`` (seconds); KeyError for an unknown name."""
        if name not in Timeouts.model_fields:
            raise KeyError(name)
        return float(getattr(self.timeouts, name))

    def stop_timeout(self, stop: Stop) -> float:
        return stop.content_timeout or self.timeouts.content

    def tour_plan(self) -> TourPlan:
        """What the one count of tours needs of this site (:mod:`frog_bt.model.ledger`)."""
        waypoints = {}
        for stop in self.tour.stops:
            waypoints[stop.poi] = stop.poi
            for variant in self.variants.get(stop.poi, ()):
                waypoints[variant.waypoint] = stop.poi
        return TourPlan(
            stops=tuple(s.poi for s in self.tour.stops),
            content=tuple(s.poi for s in self.tour.stops if s.content),
            waypoints=waypoints,
            topics={role: self.topic(role) for role in INPUTS},
            face_stops=frozenset(s.poi for s in self.tour.stops if s.face_stream),
            near=self.engagement.near,
            edge=self.engagement.edge,
            waypoint_of=self.waypoint_of,
        )


def _at(path: tuple[str | int, ...], message: str) -> PathError:
    return PathError(path, message)


def _unknown(name: str, known: list[str]) -> str:
    return f"unknown POI {name!r} (" + (
        f"known: {', '.join(known)})" if known else "no POIs are defined)"
    )


def fingerprint(site: Site) -> str:
    """The configuration as validated, hashed (sha256, 12 hex): defaults filled in, the
    file's comments and spacing not counted. Recordings carry it (provenance)."""
    return hashlib.sha256(site.model_dump_json().encode()).hexdigest()[:12]


def load_site(path: str | Path | None = None) -> Site:
    """The validated site configuration; raises ConfigError naming file and path."""
    path = Path(path) if path is not None else DEFAULT_CONFIG
    data = load_yaml(path, ConfigError)
    if not isinstance(data, dict):
        raise ConfigError(str(path), (), "expected a mapping at the top level")
    return validate(Site, data, path, ConfigError)


def hostport_problem(text: str) -> str | None:
    host, sep, port = text.rpartition(":")
    if not sep or not host:
        return "expected HOST:PORT (e.g. 127.0.0.1:5005)"
    if not port.isdigit() or not 0 <= int(port) <= 65535:
        return f"expected HOST:PORT with a port from 0 to 65535, got port {port!r}"
    return None


def parse_hostport(text: str, what: str = "address") -> tuple[str, int]:
    """``HOST:PORT`` as a tuple; UsageError naming ``what`` (the option) when malformed."""
    problem = hostport_problem(text)
    if problem:
        raise UsageError(what, text, problem)
    host, _, port = text.rpartition(":")
    return host.strip("[]"), int(port)


def ws_url_problem(text: str) -> str | None:
    """Why ``text`` is not a rosbridge WebSocket URL (``ws://HOST:PORT``); None when it is."""
    example = "expected ws://HOST:PORT, e.g. ws://127.0.0.1:9090"
    try:
        parts = urlsplit(text)
        port = parts.port
    except ValueError as exc:  # a port that is not a number or out of range
        return f"{example} ({exc})"
    if parts.scheme not in ("ws", "wss"):
        return example + (f" (not {parts.scheme}://)" if parts.scheme and "//" in text else "")
    if not parts.hostname:
        return f"{example} (no host)"
    if port == 0:
        return f"{example} (port 0)"
    return None


def check_ws_url(text: str, what: str = "--rosbridge") -> str:
    problem = ws_url_problem(text)
    if problem:
        raise UsageError(what, text, problem)
    return text
