"""A scene or sweep given as a message, a dict, a text-format or JSON string, or a file path
(.json: JSON, anything else: protobuf text format, as in the CLI) turned into its seep.v1
message. A parse error raises ValueError naming the file (or "scene text") and the parser's
line:column."""
import os

from google.protobuf import json_format, text_format


def _parse_text(text, message, origin):
    try:
        return text_format.Parse(text, message)
    except text_format.ParseError as error:
        raise ValueError("%s:%s" % (origin, error)) from None


def _parse_json(text, message, origin):
    try:
        return json_format.Parse(text, message)
    except json_format.ParseError as error:
        raise ValueError("%s: %s" % (origin, error)) from None


_FILE_ENDINGS = (".json", ".textproto", ".txtpb", ".pbtxt")


def _looks_like_path(value):
    # A one-line string without braces that names a file (or ends like one, so that a missing
    # file is reported as missing rather than as text that does not parse).
    if "\n" in value or "{" in value:
        return False
    return os.path.isfile(value) or value.endswith(_FILE_ENDINGS)


def to_message(value, message_class, what):
    """`value` as a message_class instance; `what` ("scene", "sweep") names it in errors."""
    if isinstance(value, message_class):
        return value
    message = message_class()
    if isinstance(value, dict):
        try:
            return json_format.ParseDict(value, message)
        except json_format.ParseError as error:
            raise ValueError("%s dict: %s" % (what, error)) from None
    if isinstance(value, os.PathLike) or (isinstance(value, str) and _looks_like_path(value)):
        path = os.fspath(value)
        try:
            with open(path) as f:
                text = f.read()
        except OSError as error:
            raise ValueError("%s file %s: cannot be read: %s" % (what, path, error)) from None
        if path.endswith(".json"):
            return _parse_json(text, message, path)
        return _parse_text(text, message, path)
    if isinstance(value, str):
        if value.lstrip().startswith("{"):
            return _parse_json(value, message, what + " JSON")
        return _parse_text(value, message, what + " text")
    raise TypeError("%s: expected a %s, dict, text-format or JSON string, or file path; got %s"
                    % (what, message_class.DESCRIPTOR.full_name, type(value).__name__))
