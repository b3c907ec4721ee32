#pragma once
// Rivulet's public API, all of it (docs/library.md): surfaces from particles, particle files, scenes.
#include "rivulet/error.h"
#include "rivulet/particles.h"
#include "rivulet/simulation.h"
#include "rivulet/surface.h"
#include "rivulet/version.h"
