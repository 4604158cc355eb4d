#!/usr/bin/env python3
"""Generates the add-on's view of skinpack.h: constants, enum values and struct layouts.

native.py builds its ctypes mirrors from the module this writes (`_abi.py` in the add-on zip),
so the header stays the one place where a field, a limit or a result code is defined; the
layout test (tests/blender/test_native_layout.py) still compares the result with the C compiler.
Plain Python 3, no Blender: make_zip.py calls `abi_module_source(header_text)`.

The parser knows exactly what skinpack.h uses: `#define SP_NAME integer`, `typedef enum name
{ A = 0, B, ... } name;` and `typedef struct name { type a, b[EXPR], *c; ... } name;` with
EXPR an integer expression of earlier constants. Anything else in a struct body is an error,
so a header change the generator does not understand fails the build instead of the layout.
"""

import re

SCALAR_TYPES = ("uint8_t", "uint16_t", "uint32_t", "uint64_t", "int", "float", "double", "size_t")

_COMMENTS = re.compile(r"/\*.*?\*/|//[^\n]*", re.S)
_DEFINE = re.compile(r"^\s*#define\s+(SP_[A-Z0-9_]+)\s+(-?\d+)\b", re.M)
_TYPEDEF = re.compile(r"typedef\s+(struct|enum)\s+(\w+)\s*\{(.*?)\}\s*(\w+)\s*;", re.S)
_DECLARATOR = re.compile(r"^(\**)\s*(\w+)\s*(?:\[([^\]]+)\])?$")


class HeaderError(Exception):
    pass


def _evaluate(expression, constants):
    """An integer expression of digits, known constants, + - * ( )."""
    text = re.sub(r"\b[A-Z_][A-Z0-9_]*\b", lambda m: str(constants[m.group(0)]) if m.group(0) in constants
                  else m.group(0), expression)
    if not re.fullmatch(r"[\d\s+\-*()]+", text):
        raise HeaderError("cannot evaluate %r" % expression)
    return int(eval(text, {"__builtins__": {}}))  # digits and operators only, checked above


def _parse_enum(body, constants):
    values = {}
    following = 0
    for item in (part.strip() for part in body.split(",")):
        if not item:
            continue
        name, _, value = (s.strip() for s in item.partition("="))
        following = _evaluate(value, constants) if value else following
        values[name] = following
        constants[name] = following
        following += 1
    return values


def _parse_struct(name, body, known_types, constants):
    fields = []
    for declaration in (part.strip() for part in body.split(";")):
        if not declaration:
            continue
        declaration = re.sub(r"^const\s+", "", declaration)  # const T* reads the same as T*
        match = re.match(r"^(\w+)((?:\s|\*).*)$", declaration, re.S)
        if match is None:
            raise HeaderError("%s: cannot read the field %r" % (name, declaration))
        field_type, declarators = match.groups()
        if field_type not in SCALAR_TYPES and field_type not in known_types:
            raise HeaderError("%s: unknown field type %s" % (name, field_type))
        for declarator in (d.strip() for d in declarators.strip().split(",")):
            parts = _DECLARATOR.match(declarator)
            if parts is None:
                raise HeaderError("%s: cannot read the declarator %r" % (name, declarator))
            stars, field, length = parts.groups()
            fields.append((field, field_type, len(stars), _evaluate(length, constants) if length else 0))
    return fields


def parse_header(text):
    """(constants, enums, structs): structs map a name to [(field, type, pointer depth, array
    length or 0)] in declaration order; enum and struct names map to 'enum' / 'struct'."""
    text = _COMMENTS.sub(" ", text)
    constants = {name: int(value) for name, value in _DEFINE.findall(text)}
    enums, structs, known_types = {}, {}, {}
    for kind, tag, body, name in _TYPEDEF.findall(text):
        if tag != name:
            raise HeaderError("typedef %s %s names %s" % (kind, tag, name))
        if kind == "enum":
            enums[name] = _parse_enum(body, constants)
        else:
            structs[name] = _parse_struct(name, body, known_types, constants)
        known_types[name] = kind
    return constants, enums, structs, known_types


def abi_module_source(header_text, header_name="skinpack.h"):
    constants, enums, structs, kinds = parse_header(header_text)
    lines = [
        '"""Generated from %s by addon/generate_abi.py when the add-on zip is built: do not edit."""' % header_name,
        "",
        "CONSTANTS = %r" % dict(sorted(constants.items())),
        "",
        "ENUMS = %r" % enums,
        "",
        "# name -> kind ('struct' or 'enum') of every typedef, in header order",
        "TYPES = %r" % kinds,
        "",
        "# struct -> [(field, type, pointer depth, array length or 0)] in declaration order",
        "STRUCTS = {",
    ]
    for name, fields in structs.items():
        lines.append("    %r: %r," % (name, fields))
    lines += ["}", ""]
    return "\n".join(lines)


def layout_program_source(header_text, header_name="skinpack.h"):
    """C source that prints sizeof/offsetof of every struct and field as JSON, as the compiler
    lays them out: tests/blender/test_native_layout.py compares them with the ctypes mirrors."""
    _, _, structs, _ = parse_header(header_text)
    lines = ["/* Generated from %s by addon/generate_abi.py: do not edit. */" % header_name,
             "#include <stddef.h>", "#include <stdio.h>", "", '#include "%s"' % header_name, "",
             "int main(void)", "{", '    printf("{");']
    for number, (name, fields) in enumerate(structs.items()):
        lines.append('    printf("%s\\"%s\\": {\\"size\\": %%zu, \\"fields\\": {", sizeof(%s));'
                     % (", " if number else "", name, name))
        for index, field in enumerate(fields):
            lines.append('    printf("%s\\"%s\\": %%zu", offsetof(%s, %s));'
                         % (", " if index else "", field[0], name, field[0]))
        lines.append('    printf("}}");')
    lines += ['    printf("}\\n");', "    return 0;", "}", ""]
    return "\n".join(lines)


def main():
    import argparse
    parser = argparse.ArgumentParser(description="skinpack.h -> _abi.py (default) or the layout program")
    parser.add_argument("header")
    parser.add_argument("--layout-c", action="store_true", help="write the C layout program instead")
    parser.add_argument("--output", required=True)
    args = parser.parse_args()
    with open(args.header, encoding="utf-8") as handle:
        text = handle.read()
    source = layout_program_source(text) if args.layout_c else abi_module_source(text)
    with open(args.output, "w", encoding="utf-8") as handle:
        handle.write(source)


if __name__ == "__main__":
    main()
