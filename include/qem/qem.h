// The whole public API of qem in one include.
#pragma once

#include "qem/analyze.h"
#include "qem/cluster.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/mesh.h"
#include "qem/mesh_info.h"
#include "qem/progressive.h"
#include "qem/refit.h"
#include "qem/simplify.h"
