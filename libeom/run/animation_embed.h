/* animation_embed.h - the animation page's template and three.js, as
 * text compiled into the run layer (animation_embed.c, made at build time
 * by animation_embed.py from animation_page.html and, when the build
 * found it, three.js and its licence; otherwise those two are ""). */
#ifndef EOM_RUN_ANIMATION_EMBED_H
#define EOM_RUN_ANIMATION_EMBED_H

extern const char eom__anim_template[];
extern const char eom__anim_three[];
extern const char eom__anim_three_license[];
extern const char eom__anim_three_version[];

#endif /* EOM_RUN_ANIMATION_EMBED_H */
