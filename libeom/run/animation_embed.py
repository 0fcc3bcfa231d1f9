#!/usr/bin/env python3
"""animation_embed.py - write animation_embed.c: the animation page's
template and, when given, three.js, its licence and its version, as C
arrays of bytes (animation_embed.h). Arrays, not string literals: ISO C
promises only 4095 characters per literal.

usage: animation_embed.py OUT.c TEMPLATE.html [THREE.js LICENSE VERSION]
"""
import sys


def array(out, name, data):
    out.write("const char %s[] = {\n" % name)
    for i in range(0, len(data), 24):
        # char may be signed: bytes above 127 written as their negative
        out.write(",".join(str(b if b < 128 else b - 256)
                           for b in data[i:i + 24]) + ",\n")
    out.write("0};\n")


def main():
    if len(sys.argv) not in (3, 6):
        sys.exit(__doc__)
    with open(sys.argv[2], "rb") as f:
        template = f.read()
    three = lic = version = b""
    if len(sys.argv) == 6:
        with open(sys.argv[3], "rb") as f:
            three = f.read()
        with open(sys.argv[4], "rb") as f:
            lic = f.read()
        version = sys.argv[5].encode()
        # the page holds them inside a script element and a comment
        if b"</script" in three.lower() or b"*/" in lic:
            sys.exit("animation_embed.py: three.js or its licence would "
                     "end the page's script early")
    with open(sys.argv[1], "w") as out:
        out.write("/* made by animation_embed.py: do not edit */\n")
        out.write('#include "animation_embed.h"\n')
        array(out, "eom__anim_template", template)
        array(out, "eom__anim_three", three)
        array(out, "eom__anim_three_license", lic)
        array(out, "eom__anim_three_version", version)


main()
