"""Reading SUMO's XML files, plain or gzip-compressed, with one error line naming the file."""

from __future__ import annotations

import gzip
import xml.etree.ElementTree as ET
from pathlib import Path

from eoam_sumo.errors import InputError


def xml_source(path: Path):
    """The file to parse: SUMO reads gzip-compressed XML (``*.gz``) too."""
    return gzip.open(path) if path.suffix == ".gz" else path


def parse_xml(path: Path, what: str) -> ET.Element:
    """Root element of an XML file; InputError naming ``what`` and the file if missing or
    malformed."""
    if not path.is_file():
        raise InputError(f"{what} {path} not found")
    try:
        return ET.parse(xml_source(path)).getroot()
    except (ET.ParseError, OSError) as exc:
        raise InputError(f"{path}: malformed XML: {exc}") from exc
