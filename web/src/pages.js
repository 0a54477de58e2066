// The weight pages' shape on the GPU: the layers of one array texture, each the size of the
// largest page (the material allocates it, the loader counts its bytes).
export function pageLayers(pages) {
  return {
    width: Math.max(...pages.map((t) => t.image.width)),
    height: Math.max(...pages.map((t) => t.image.height)),
    depth: pages.length,
  };
}
