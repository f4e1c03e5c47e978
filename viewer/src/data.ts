// Loading an output folder (docs/viewer-format.md): scene.glb, layers.json and summary.json,
// either over HTTP (served by `clod view`, or any static server) or from files the user picks
// or drops (a page opened from file:// may not fetch its neighbours).

/** layers.json, format "clod-layers" version 1. Every part but `format`/`version` is optional. */
export interface LayersFile {
  format: string;
  version: number;
  frames?: {
    time: number[];
    kinetic_energy?: number[];
    potential_energy?: number[];
    total_energy?: number[];
    contacts?: number[];
    tests_spent?: number[];
    tests_budget?: number[];
  };
  contacts?: { frame_offsets: number[]; data: number[] };
  bodies?: BodyLayers[];
}

export interface BodyLayers {
  name: string;
  node: number;
  sphere_tree?: { levels: number[][] };
  cfm_samples?: { level: number; points: number[]; normals: number[] }[];
  contact_tree?: { cells: number[]; halfspaces?: number[] };
}

export interface Summary {
  bodies?: { name: string; position?: number[]; orientation?: number[] }[];
  steps?: number;
  dt?: number;
  [key: string]: unknown;
}

export interface OutputFolder {
  label: string;
  glb: ArrayBuffer;
  layers: LayersFile | null;
  summary: Summary | null;
}

export class LoadError extends Error {}

function checkLayers(value: unknown, source: string): LayersFile {
  const layers = value as LayersFile;
  if (!layers || typeof layers !== 'object' || layers.format !== 'clod-layers')
    throw new LoadError(`${source}: not a clod layers file (format must be "clod-layers")`);
  if (layers.version !== 1) throw new LoadError(`${source}: layers version ${layers.version} is not supported (expected 1)`);
  return layers;
}

function parseJson(text: string, source: string): unknown {
  try {
    return JSON.parse(text);
  } catch (e) {
    throw new LoadError(`${source}: malformed JSON (${(e as Error).message})`);
  }
}

/** Fetches an output folder from `baseUrl` (ending in '/'). scene.glb is required. */
export async function fetchFolder(baseUrl: string): Promise<OutputFolder> {
  const get = async (name: string, required: boolean): Promise<Response | null> => {
    let response: Response;
    try {
      response = await fetch(baseUrl + name, { cache: 'no-store' });
    } catch (e) {
      if (required) throw new LoadError(`cannot fetch ${baseUrl}${name}: ${(e as Error).message}`);
      return null;
    }
    if (!response.ok) {
      if (required) throw new LoadError(`cannot fetch ${baseUrl}${name}: HTTP ${response.status}`);
      return null;
    }
    return response;
  };
  const [glbResponse, layersResponse, summaryResponse] = await Promise.all([
    get('scene.glb', true),
    get('layers.json', false),
    get('summary.json', false),
  ]);
  const glb = await glbResponse!.arrayBuffer();
  const layers = layersResponse ? checkLayers(parseJson(await layersResponse.text(), 'layers.json'), 'layers.json') : null;
  const summary = summaryResponse ? (parseJson(await summaryResponse.text(), 'summary.json') as Summary) : null;
  return { label: baseUrl, glb, layers, summary };
}

/** Builds an output folder from user-chosen files (matched by base name). */
export async function readFiles(files: File[]): Promise<OutputFolder> {
  const byName = new Map<string, File>();
  for (const f of files) byName.set(f.name, f);
  const glbFile = byName.get('scene.glb') ?? files.find((f) => f.name.toLowerCase().endsWith('.glb'));
  if (!glbFile) throw new LoadError('no scene.glb among the chosen files: pick the output folder of clod simulate --gltf');
  const layersFile = byName.get('layers.json');
  const summaryFile = byName.get('summary.json');
  const layers = layersFile ? checkLayers(parseJson(await layersFile.text(), layersFile.name), layersFile.name) : null;
  const summary = summaryFile ? (parseJson(await summaryFile.text(), summaryFile.name) as Summary) : null;
  const folder = (glbFile as File & { webkitRelativePath?: string }).webkitRelativePath?.split('/')[0];
  return { label: folder || glbFile.name, glb: await glbFile.arrayBuffer(), layers, summary };
}

/** The files of a drop: plain files, or the first level of dropped folders. */
export async function filesFromDrop(dt: DataTransfer): Promise<File[]> {
  const entries: FileSystemEntry[] = [];
  for (const item of Array.from(dt.items)) {
    const entry = item.webkitGetAsEntry?.();
    if (entry) entries.push(entry);
  }
  if (entries.length === 0) return Array.from(dt.files);
  const files: File[] = [];
  const fileOf = (e: FileSystemFileEntry) => new Promise<File>((resolve, reject) => e.file(resolve, reject));
  for (const entry of entries) {
    if (entry.isFile) {
      files.push(await fileOf(entry as FileSystemFileEntry));
    } else if (entry.isDirectory) {
      const reader = (entry as FileSystemDirectoryEntry).createReader();
      for (;;) {
        const batch = await new Promise<FileSystemEntry[]>((resolve, reject) => reader.readEntries(resolve, reject));
        if (batch.length === 0) break;
        for (const e of batch) if (e.isFile) files.push(await fileOf(e as FileSystemFileEntry));
      }
    }
  }
  return files;
}
