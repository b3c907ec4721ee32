#pragma once
// Rivulet's public API, all of it (docs/library.md): surfaces from particles, the frame pipeline, particle
// files, scenes, recordings.
#include "rivulet/error.h"
#include "rivulet/particles.h"
#include "rivulet/pipeline.h"
#include "rivulet/recording.h"
#include "rivulet/simulation.h"
#include "rivulet/surface.h"
#include "rivulet/version.h"
