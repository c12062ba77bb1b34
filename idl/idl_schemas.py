#!/usr/bin/env python3
"""Every navbus struct's self-contained schema, for recordings that tools decode by themselves
(navbus record --format mcap). Run at build time by idl/CMakeLists.txt:

    idl_schemas.py OUT_HEADER OUT_SOURCE IDL_FILE...

Two texts per struct `navbus::T`, declared in the IDL file F:
  omgidl   F with its #include files inlined (each once), comments and preprocessor lines
           removed: one OMG IDL source with every type T refers to, as the MCAP registry's
           `omgidl` schema encoding asks;
  ros2msg  the ROS 2 message definition of T (`navbus/msg/T`), then each struct it uses after a
           line of 80 '=' and `MSG: navbus/<S>`, as the registry's `ros2msg` encoding asks.
           IDL enums become uint32 (their XCDR1 size) with their enumerators as constants, the
           file's `const` declarations become constants of its structs, sequence<T, N> becomes
           T[<=N], string<N> string<=N, arrays T[N].
The IDL subset is the one navbus uses (modules, enums, consts, structs of basic types, arrays,
bounded sequences and strings, @key/@final annotations); anything else stops the build with
the file and the token.
"""
import pathlib
import re
import sys

BASIC = {
    ("unsigned", "long", "long"): "uint64", ("unsigned", "long"): "uint32",
    ("unsigned", "short"): "uint16", ("long", "long"): "int64", ("long",): "int32",
    ("short",): "int16", ("double",): "float64", ("float",): "float32",
    ("boolean",): "bool", ("octet",): "byte", ("char",): "char",
}
DELIMITER = "=" * 80
TOKEN = re.compile(r"\s*(::|[A-Za-z_]\w*|-?\d+|[{}<>;,=\[\]@()])")


def flatten(path, seen):
    """The file's text with its #include "X.idl" files inlined once, no preprocessor lines."""
    if path in seen:
        return ""
    seen.add(path)
    out = []
    for line in path.read_text().splitlines():
        include = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
        if include:
            out.append(flatten(path.parent / include.group(1), seen))
        elif not line.lstrip().startswith("#"):
            out.append(line)
    return "\n".join(out)


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    return "\n".join(line.rstrip() for line in text.splitlines() if line.strip()) + "\n"


class Parser:
    """Enums, consts and structs of one flattened, comment-free IDL text."""

    def __init__(self, text, where):
        self.where = where
        self.tokens, pos = [], 0
        text = text.rstrip()
        while pos < len(text):
            m = TOKEN.match(text, pos)
            if not m:
                self.fail(f"unexpected text {text[pos:pos + 20]!r}")
            self.tokens.append(m.group(1))
            pos = m.end()
        self.i = 0
        self.enums, self.consts, self.structs = {}, [], {}

    def fail(self, what):
        sys.exit(f"idl_schemas.py: {self.where}: {what}")

    def peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else None

    def take(self, expected=None):
        tok = self.peek()
        if tok is None or (expected is not None and tok != expected):
            self.fail(f"expected {expected!r}, found {tok!r}")
        self.i += 1
        return tok

    def annotations(self):
        while self.peek() == "@":
            self.take("@")
            self.take()
            if self.peek() == "(":
                while self.take() != ")":
                    pass

    def definitions(self, module):
        while self.peek() not in (None, "}"):
            self.annotations()
            kind = self.take()
            if kind == "module":
                name = self.take()
                self.take("{")
                self.definitions(module + [name])
                self.take("}")
            elif kind == "enum":
                name = self.take()
                self.take("{")
                values = [self.take()]
                while self.peek() == ",":
                    self.take(",")
                    values.append(self.take())
                self.take("}")
                self.enums["::".join(module + [name])] = values
            elif kind == "const":
                type_ = self.type_spec()
                name = self.take()
                self.take("=")
                self.consts.append((type_, name, self.take()))
            elif kind == "struct":
                name = self.take()
                self.take("{")
                members = []
                while self.peek() != "}":
                    self.annotations()
                    type_ = self.type_spec()
                    field = self.take()
                    if self.peek() == "[":
                        self.take("[")
                        type_ = ("array", type_, self.take())
                        self.take("]")
                    self.take(";")
                    members.append((type_, field))
                self.take("}")
                self.structs["::".join(module + [name])] = (module, members)
            else:
                self.fail(f"unsupported definition {kind!r}")
            self.take(";")

    def type_spec(self):
        words = []
        while self.peek() in ("unsigned", "long", "short", "double", "float", "boolean", "octet",
                              "char"):
            words.append(self.take())
        if words:
            if tuple(words) not in BASIC:
                self.fail(f"unsupported type {' '.join(words)!r}")
            return ("basic", BASIC[tuple(words)])
        tok = self.take()
        if tok == "string":
            bound = None
            if self.peek() == "<":
                self.take("<")
                bound = self.take()
                self.take(">")
            return ("string", bound)
        if tok == "sequence":
            self.take("<")
            element = self.type_spec()
            bound = None
            if self.peek() == ",":
                self.take(",")
                bound = self.take()
            self.take(">")
            return ("sequence", element, bound)
        name = [tok]
        while self.peek() == "::":
            self.take("::")
            name.append(self.take())
        return ("named", "::".join(name))


def resolve(parser, module, name):
    """The scoped name a type name refers to from inside `module`."""
    for depth in range(len(module), -1, -1):
        scoped = "::".join(module[:depth] + [name])
        if scoped in parser.structs or scoped in parser.enums:
            return scoped
    parser.fail(f"unknown type {name!r}")


def msg_type(parser, module, t, used_structs, used_enums):
    kind = t[0]
    if kind == "basic":
        return t[1]
    if kind == "string":
        return "string" if t[1] is None else f"string<={t[1]}"
    if kind == "array":
        return f"{msg_type(parser, module, t[1], used_structs, used_enums)}[{t[2]}]"
    if kind == "sequence":
        element = msg_type(parser, module, t[1], used_structs, used_enums)
        return f"{element}[]" if t[2] is None else f"{element}[<={t[2]}]"
    scoped = resolve(parser, module, t[1])
    if scoped in parser.enums:
        used_enums.append(scoped)
        return "uint32"
    used_structs.append(scoped)
    return "/".join(scoped.split("::"))


def msg_text(parser, scoped):
    """One .msg file (fields, then constants) and the structs it uses."""
    module, members = parser.structs[scoped]
    used_structs, used_enums, fields = [], [], []
    for type_, field in members:
        fields.append(f"{msg_type(parser, module, type_, used_structs, used_enums)} {field}")
    constants = []
    for enum in dict.fromkeys(used_enums):
        constants += [f"uint32 {value}={i}" for i, value in enumerate(parser.enums[enum])]
    for type_, name, value in parser.consts:
        constants.append(f"{msg_type(parser, module, type_, [], [])} {name}={value}")
    return "\n".join(constants + fields) + "\n", used_structs


def ros2msg(parser, scoped):
    text, pending = msg_text(parser, scoped)
    done = {scoped}
    while pending:
        dependency = pending.pop(0)
        if dependency in done:
            continue
        done.add(dependency)
        dep_text, more = msg_text(parser, dependency)
        text += f"{DELIMITER}\nMSG: {'/'.join(dependency.split('::'))}\n{dep_text}"
        pending += more
    return text


def cxx_string(text):
    assert ")schema\"" not in text
    return f'R"schema({text})schema"'


def main():
    header, source, *idl_files = sys.argv[1:]
    entries = []
    for idl in map(pathlib.Path, idl_files):
        omgidl = strip_comments(flatten(idl, set()))
        parser = Parser(omgidl, idl.name)
        parser.definitions([])
        # Structs declared in this file (the included files' are theirs).
        own = Parser(strip_comments(flatten(idl, {p for p in idl.parent.glob("*.idl")
                                                    if p != idl})), idl.name)
        own.definitions([])
        # The file's own consts belong to its structs; included files' consts to theirs.
        parser.consts = own.consts
        for scoped in own.structs:
            package, name = scoped.split("::")[0], scoped.split("::")[-1]
            entries.append((scoped, f"{package}/msg/{name}", omgidl, ros2msg(parser, scoped)))
    pathlib.Path(header).write_text(
        "// Generated at build time by idl/idl_schemas.py: every navbus struct's self-contained\n"
        "// OMG IDL and ROS 2 message definition (MCAP schema encodings omgidl and ros2msg).\n"
        "#pragma once\n\n#include <string_view>\n\nnamespace navbus::idl_schemas {\n\n"
        "struct TypeSchema {\n"
        "  std::string_view type_name;  ///< e.g. navbus::ImuIncrement\n"
        "  std::string_view ros2_name;  ///< e.g. navbus/msg/ImuIncrement\n"
        "  std::string_view omgidl;     ///< one IDL source defining the type and what it uses\n"
        "  std::string_view ros2msg;    ///< the .msg definition, then its dependencies\n"
        "};\n\n/// nullptr for a type that is not a navbus struct.\n"
        "const TypeSchema* find(std::string_view type_name);\n\n}  // namespace navbus::idl_schemas\n")
    rows = ",\n".join(
        f'    {{"{s}", "{r}",\n     {cxx_string(o)},\n     {cxx_string(m)}}}'
        for s, r, o, m in entries)
    pathlib.Path(source).write_text(
        "// Generated at build time by idl/idl_schemas.py from the IDL files.\n"
        '#include "IdlSchemas.h"\n\nnamespace navbus::idl_schemas {\nnamespace {\n'
        f"const TypeSchema kSchemas[] = {{\n{rows}}};\n}}  // namespace\n\n"
        "const TypeSchema* find(std::string_view type_name) {\n"
        "  for (const TypeSchema& s : kSchemas) {\n"
        "    if (s.type_name == type_name) return &s;\n  }\n  return nullptr;\n}\n\n"
        "}  // namespace navbus::idl_schemas\n")


if __name__ == "__main__":
    main()
