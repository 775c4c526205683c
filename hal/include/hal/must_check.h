#ifndef HAL_MUST_CHECK_H
#define HAL_MUST_CHECK_H

/* A result the caller must look at: a store that did not save, a slot that
 * did not take its bytes, a move that was refused. Here, in the lowest layer,
 * so every layer above can mark its own. */
#if defined(__GNUC__)
#define MUST_CHECK __attribute__((warn_unused_result))
#else
#define MUST_CHECK
#endif

#endif
