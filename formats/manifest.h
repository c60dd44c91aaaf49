// Placeholder: the manifest and writers land with the bake.
#pragma once
