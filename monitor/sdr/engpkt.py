"""Engineering-packet files: the decoded EP XML of LW-GEO and a YAML file of the same content.

Both hold angles in microradians under the EP's own element names; the model
(:class:`monitor.geometry.ep_model.EngineeringPacket`) holds radians. The table ``_ANGLES`` says
where each model field lives in a file, so XML and YAML are read by the same code. The mounting
angles are not part of a real EP: for XML they come from ``MOUNTING_URAD`` by ``InstrumentId``, a
YAML file carries them under ``ScToSbf``. Writing keeps the input's format: an XML output is the input
text with the two scene-mirror angle lists replaced and a provenance comment added.
"""

from __future__ import annotations

import json
import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import ArrayLike

from monitor.core.constants import N_FOR, N_FOV, URAD
from monitor.core.errors import DataError
from monitor.core.satellites import SATELLITES
from monitor.geometry.ep_model import EngineeringPacket

# (model field, path in the EP, number of values); a triple/pair path lists its components.
_ANGLES = (
    ("fov_crosstrack_offset_rad", "FovParam/Lw/CrosstrackOffsetAngle", N_FOV),
    ("fov_intrack_offset_rad", "FovParam/Lw/IntrackOffsetAngle", N_FOV),
    ("fov_size_rad", "FovParam/Lw/Size", N_FOV),
    ("los_relative_yaw_rad", "FovParam/Lw/LosRelativeYaw", None),
    ("los_relative_pitch_rad", "FovParam/Lw/LosRelativePitch", None),
    ("ssm_crosstrack_roll_rad", "MappingParameters/ActualCrosstrackAngleRoll", N_FOR),
    ("ssm_intrack_pitch_rad", "MappingParameters/ActualIntrackAnglePitch", N_FOR),
    ("ifr_boresight_to_ssmf_rad", ("MappingParameters/IfrBoresightToSsmf", ("Yaw", "Pitch")), 2),
    ("ssmr_to_ssmf_rad", ("MappingParameters/SsmrToSsmf", ("Roll", "Pitch", "Yaw")), 3),
    ("iar_to_ssmr_rad", ("MappingParameters/IarToSsmr", ("Roll", "Pitch", "Yaw")), 3),
    ("sbf_to_iar_rad", ("MappingParameters/SbfToIar", ("Roll", "Pitch", "Yaw")), 3),
)
_TIME_STAMP_BIAS = "MappingParameters/TimeStampBias"  # milliseconds
_MOUNTING = ("ScToSbf", ("Roll", "Pitch", "Yaw"))

# InstrumentId -> satellite, the PCT mounting (roll, pitch, yaw) in urad (LW-GEO cris_sensor_info) and the
# packaged real EPs: from the satellite table
INSTRUMENT_SATELLITE = {s.cris_instrument_id: s.short for s in SATELLITES.values() if s.cris_instrument_id}
MOUNTING_URAD = {s.short: s.pct_mounting_urad for s in SATELLITES.values() if s.pct_mounting_urad}
PACKAGED = {s.short: s.ep_file for s in SATELLITES.values() if s.ep_file}


class EngPktError(DataError):
    """A malformed EP file; the message names the file, the field and the value.

    Parameters
    ----------
    path : object
        The file.
    field : str
        The element.
    problem : str
        What is wrong.
    """

    def __init__(self, path: object, field: str, problem: str) -> None:
        super().__init__(f"{path}: {field}: {problem}")


def _numbers(path: object, name: str, text: object, n: int | None) -> float | list[float]:
    try:
        values = [float(v) for v in str(text).replace(",", " ").split()]
    except ValueError:
        raise EngPktError(path, name, f"not numbers: {str(text)[:60]!r}") from None
    if n is None:
        if len(values) != 1:
            raise EngPktError(path, name, f"expected one value, got {len(values)}")
        return values[0]
    if len(values) != n:
        raise EngPktError(path, name, f"expected {n} values, got {len(values)}")
    if not np.all(np.isfinite(values)):
        raise EngPktError(path, name, f"non-finite value in {values}")
    return values


class _XmlSource:
    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        try:
            self.root = ET.fromstring(text)
        except ET.ParseError as exc:
            raise EngPktError(path, "XML", str(exc)) from None
        if self.root.tag != "EngPkt":
            raise EngPktError(path, "root element", f"{self.root.tag!r}, expected 'EngPkt'")

    def get(self, name: str) -> str:
        node = self.root.find(name)
        if node is None or node.text is None:
            raise EngPktError(self.path, name, "missing")
        return node.text


class _YamlSource:
    def __init__(self, path: Path, doc: object) -> None:
        self.path = path
        self.doc = doc

    def get(self, name: str) -> str:
        node = self.doc
        for part in name.split("/"):
            if not isinstance(node, dict) or part not in node:
                raise EngPktError(self.path, name, "missing")
            node = node[part]
        return " ".join(str(v) for v in node) if isinstance(node, list) else str(node)


def _read_angles(src: _XmlSource | _YamlSource, path: Path) -> dict[str, Any]:
    kw: dict[str, Any] = {}
    for field, where, n in _ANGLES:
        values: float | list[float] | list[float | list[float]]
        if isinstance(where, tuple):
            group, parts = where
            values = [_numbers(path, f"{group}/{p}", src.get(f"{group}/{p}"), None) for p in parts]
        else:
            values = _numbers(path, where, src.get(where), n)
        kw[field] = np.asarray(values, float) * URAD
    kw["time_stamp_bias_ms"] = _numbers(path, _TIME_STAMP_BIAS, src.get(_TIME_STAMP_BIAS), None)
    return kw


def _build(
    path: Path, kw: dict[str, Any], satellite: str, version: str, provenance: dict
) -> EngineeringPacket:
    try:
        return EngineeringPacket(satellite=satellite, version=version, provenance=provenance, **kw)
    except ValueError as exc:
        raise EngPktError(path, "angles", str(exc)) from None


def load_ep(path: str | os.PathLike[str], satellite: str | None = None) -> EngineeringPacket:
    """Read an EP from a decoded EP XML file or a YAML file of the same content.

    *satellite* (npp, j01, j02) overrides the satellite found in the file (XML: by InstrumentId).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    satellite : str, optional
        ``npp``, ``j01`` or ``j02``: overrides the satellite found in the file.

    Returns
    -------
    EngineeringPacket
        The packet; an :class:`EngPktError` names the file and element.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise EngPktError(path, "file", f"unreadable ({exc.strerror})") from None
    if text.lstrip().startswith("<"):
        src = _XmlSource(path, text)
        try:
            instrument = int(src.get("InstrumentId"))
        except ValueError:
            raise EngPktError(path, "InstrumentId", f"not an integer: {src.get('InstrumentId')!r}") from None
        sat = satellite or INSTRUMENT_SATELLITE.get(instrument)
        if sat is None:
            raise EngPktError(
                path, "InstrumentId", f"{instrument} is not a known instrument; pass the satellite"
            )
        if sat not in MOUNTING_URAD:
            raise EngPktError(path, "mounting", f"no spacecraft mounting angles known for {sat}")
        kw = _read_angles(src, path)
        kw["sc_to_sbf_rad"] = np.asarray(MOUNTING_URAD[sat], float) * URAD
        return _build(path, kw, sat, f"V{src.get('PktVersion').strip()}", {"source": path.name})
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise EngPktError(path, "YAML", str(exc).splitlines()[0]) from None
    if not isinstance(doc, dict):
        raise EngPktError(path, "document", "not an EP mapping (FovParam, MappingParameters, ScToSbf)")
    ysrc = _YamlSource(path, doc)
    kw = _read_angles(ysrc, path)
    group, parts = _MOUNTING
    kw["sc_to_sbf_rad"] = (
        np.asarray([_numbers(path, f"{group}/{p}", ysrc.get(f"{group}/{p}"), None) for p in parts]) * URAD
    )
    sat = satellite or doc.get("satellite")
    if sat not in SATELLITES:
        raise EngPktError(path, "satellite", f"{sat!r}, expected one of {', '.join(SATELLITES)}")
    return _build(path, kw, sat, str(doc.get("version", path.stem)), dict(doc.get("provenance") or {}))


def packaged_ep(satellite: str) -> EngineeringPacket:
    """The real EP shipped in the package for *satellite* (S-NPP V37, NOAA-20 V115).

    Parameters
    ----------
    satellite : str
        ``npp`` or ``j01`` (``j02``: a stand-in).

    Returns
    -------
    EngineeringPacket
        The packet.
    """
    if satellite not in PACKAGED:
        raise KeyError(f"no real engineering packet is shipped for {satellite!r} (have {sorted(PACKAGED)})")
    return load_ep(packaged_path(satellite))


def packaged_path(satellite: str) -> Path:
    """Where the real EP shipped for *satellite* lies in the installed package.

    Parameters
    ----------
    satellite : str
        The satellite's short name.

    Returns
    -------
    Path
        The file.
    """
    return Path(str(resources.files("monitor.data.ep") / PACKAGED[satellite]))


def _urad(values: ArrayLike) -> list[float | int]:
    out = np.round(np.asarray(values, float) / URAD, 6)
    return [float(v) if v != int(v) else int(v) for v in np.atleast_1d(out)]


def ep_to_yaml_doc(ep: EngineeringPacket) -> dict:
    """The YAML document of *ep*: the EP element names, values in urad (the time-stamp bias in ms).

    Parameters
    ----------
    ep : EngineeringPacket
        The packet.

    Returns
    -------
    dict
        The document.
    """
    doc = {
        "satellite": ep.satellite,
        "version": ep.version,
        "units": "urad; TimeStampBias in ms",
        "provenance": ep.provenance,
    }
    for field, where, n in _ANGLES:
        value = _urad(getattr(ep, field))
        if isinstance(where, tuple):
            group, parts = where
            node = _subtree(doc, group)
            for p, v in zip(parts, value, strict=True):
                node[p] = v
        else:
            group, leaf = where.rsplit("/", 1)
            _subtree(doc, group)[leaf] = value if n is not None else value[0]
    _subtree(doc, "MappingParameters")["TimeStampBias"] = float(ep.time_stamp_bias_ms)
    doc["ScToSbf"] = dict(zip(_MOUNTING[1], _urad(ep.sc_to_sbf_rad), strict=True))
    return doc


def _subtree(doc: dict, path: str) -> dict:
    node = doc
    for part in path.split("/"):
        node = node.setdefault(part, {})
    return node


def _provenance_comment(ep: EngineeringPacket) -> str:
    return json.dumps(ep.provenance, indent=1, sort_keys=True).replace("--", "- -")


def save_ep(
    ep: EngineeringPacket, out_path: str | os.PathLike[str], like: str | os.PathLike[str] | None = None
) -> Path:
    """Write *ep* in the format of the file *like* (XML or YAML; YAML when *like* is None).

    XML: the text of *like* with ActualCrosstrackAngleRoll and ActualIntrackAnglePitch replaced (whole
    microradians, as the EP stores them) and the provenance as a comment after the declaration; every
    other element is kept byte for byte.

    Parameters
    ----------
    ep : EngineeringPacket
        The packet.
    out_path : str or os.PathLike
        Where to write it.
    like : str or os.PathLike, optional
        The file whose format, and for XML whose text, it keeps.

    Returns
    -------
    Path
        The file written.
    """
    out = Path(out_path)
    if like is not None and Path(like).read_text().lstrip().startswith("<"):
        text = Path(like).read_text()
        for name, values in (
            ("ActualCrosstrackAngleRoll", ep.ssm_crosstrack_roll_rad),
            ("ActualIntrackAnglePitch", ep.ssm_intrack_pitch_rad),
        ):
            joined = " ".join(str(int(v)) for v in np.round(values / URAD))
            text, count = re.subn(rf"(<{name}>)[^<]*(</{name}>)", rf"\g<1>{joined}\g<2>", text)
            if count != 1:
                raise EngPktError(like, f"MappingParameters/{name}", f"found {count} times, expected once")
        comment = f"<!-- crisgeo provenance\n{_provenance_comment(ep)}\n-->\n"
        head, sep, rest = text.partition("?>\n")
        text = head + sep + comment + rest if sep else comment + text
        out.write_text(text)
        return out
    header = "# CrIS engineering packet (crisgeo YAML form of the EP XML; angles in urad)\n"
    out.write_text(
        header + yaml.safe_dump(ep_to_yaml_doc(ep), sort_keys=False, width=200, default_flow_style=None)
    )
    return out


def load_library(paths: Iterable[str | os.PathLike[str]]) -> tuple[dict[str, EngineeringPacket], list[str]]:
    """EPs from files and directories (``*.xml``, ``*.yaml``, ``*.yml``): ({name: EP}, [problems]).

    With no paths the library is the real EPs shipped in the package; unreadable files are reported,
    not fatal.

    Parameters
    ----------
    paths : iterable of str or os.PathLike
        EP files or directories.

    Returns
    -------
    library : dict of str to EngineeringPacket
        By name.
    problems : list of str
        The files that could not be read, with why.
    """
    paths = list(paths)
    library = {} if paths else {PACKAGED[sat]: load_ep(packaged_path(sat)) for sat in PACKAGED}
    problems = []
    for p in map(Path, paths):
        if not p.exists():
            problems.append(f"{p}: no such file or directory")
            continue
        files = sorted(f for f in p.iterdir() if f.suffix in (".xml", ".yaml", ".yml")) if p.is_dir() else [p]
        for f in files:
            try:
                library[f.name] = load_ep(f)
            except EngPktError as exc:
                problems.append(str(exc))
    return library, problems
