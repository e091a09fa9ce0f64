// Types of the wasm module's JS API (wasm/bind_*.cpp), the worker protocol (lib/protocol.js) and
// the mesh ops (ops/mesh.js). Documentation only: the page is plain JS, editors and
// reviewers read this. Engineers adding bind_<module>.cpp / ops/<module>.js extend
// MeshMorphModule and add their op types below.

/** Every binding failure; the JS wrapper (lib/errors.js unwrap) throws MeshMorphError with it. */
export interface Failure {
  ok: false;
  /** StatusCode name (core/common/status.h): InvalidArgument, InvalidMesh, IoError, ParseError,
   *  Unsupported, FactorizationFailed, NotConverged, NumericalError, Cancelled; or, from the one
   *  guard every binding goes through (wasm/guard.h), Internal (a C++ exception escaped: a bug)
   *  and OutOfMemory (the 4 GB heap is exhausted). */
  code: string;
  /** A sentence a user can act on, e.g. "mesh has 12 non-manifold edges, first at vertices 10-11". */
  message: string;
}
export type Result<T> = ({ ok: true } & T) | Failure;

export interface DefectReport {
  id: 'Empty' | 'NonFiniteCoordinate' | 'IndexOutOfRange' | 'DegenerateFace' | 'DuplicateFace'
    | 'NonManifoldEdge' | 'NonManifoldVertex' | 'UnreferencedVertex' | 'InconsistentOrientation';
  name: string;     // human wording, as in `meshmorph info`
  count: number;
  example: string;  // first instance, e.g. "face 17 (vertices 3, 3, 9)"
}

/** core/mesh/validate.h MeshReport. */
export interface MeshReport {
  vertices: number; faces: number; edges: number;
  bboxMin: [number, number, number]; bboxMax: [number, number, number]; bboxDiagonal: number;
  components: number; componentSizes: number[];
  boundaryLoopLengths: number[]; eulerCharacteristic: number; closed: boolean;
  defects: DefectReport[];
}

export interface PrimitiveInfo {
  name: string; node: number; mesh: number; primitive: number;
  firstVertex: number; numVertices: number; firstFace: number; numFaces: number; skinned: boolean;
}

/** io::LoadOptions with C++ field names; every field optional (core defaults). */
export interface LoadOptions {
  weld?: { tolerance?: number; drop_degenerate_faces?: boolean };
  skip_unsupported_primitives?: boolean;
}

/** core/spectral/spectral_basis.h SpectralBasisOptions. */
export interface SpectralBasisOptions {
  k?: number; ncv?: number; relative_shift?: number; tolerance?: number; max_iterations?: number;
  /** 'auto' (default): block Lanczos when the Krylov basis exceeds 20 MiB, else Spectra's. */
  solver?: 'auto' | 'block' | 'spectra';
}

/** The Emscripten module (meshmorph_web.mjs in the worker, meshmorph_node.cjs in tests).
 *  Embind checks argument counts: pass `undefined` for an optional argument, never omit it. */
/** One option of a job, from its schema (app/option_schema.h): the same description gives the
 *  CLI its flags and --help, the bindings their option parsing, and the page its options panels. */
export interface OptionDescription {
  name: string;                 // key in the options object of the job's binding / op
  kind: 'integer' | 'number' | 'boolean' | 'choice' | 'text';
  default: number | boolean | string;
  min?: number; max?: number;   // inclusive (integer, number)
  choices?: string[];           // choice
  flag: string;                 // the CLI flag, e.g. "--cage-vertices"
  help: string;                 // one line
}
export interface OptionSchema { job: 'edit' | 'transfer' | 'transfer-parts' | 'retarget' | 'joints' | 'merge'; summary: string; options: OptionDescription[] }

export interface MeshMorphModule {
  /** The options schema of a job (`meshmorph options --json` prints the same). */
  optionSchema(job: string): Result<{ schema: OptionSchema }>;
  /** Loads a file by its name's extension (.glb .gltf .obj .off .ply). `files` resolves a
   *  .gltf's external URIs (exact key, then last path segment). The asset stays registered
   *  until disposeAsset. */
  loadAsset(bytes: Uint8Array, name: string, files: Record<string, Uint8Array> | undefined,
            options: LoadOptions | undefined): Result<{
    asset: number; name: string; format: string; warnings: string[]; primitives: PrimitiveInfo[];
    positions: Float32Array;      // #R·3, raw layout, world space
    indices: Uint32Array;         // #T·3 over the raw layout
    normals: Float32Array;        // #R·3, smooth normals of the welded surface
    toWelded: Uint32Array;        // #R, welded index of every raw vertex
    weldedVertices: number;       // #W
    weldedFaces: number;          // #F
    report: MeshReport;           // of the welded mesh
    text: string;                 // `meshmorph info` text (io/info_report.h)
    info: object;                 // `meshmorph info --json`
  }>;
  disposeAsset(asset: number): boolean;
  /** The asset's welded mesh, the one the algorithms work on (not in loadAsset's result: the
   *  copies are a tenth of a 1M-vertex load, and a page that only views the mesh never needs them). */
  assetWeldedMesh(asset: number): Result<{ positions: Float64Array; indices: Uint32Array }>;
  /** Writes the asset (everything in the document kept) with new welded positions (#W·3) or
   *  the loaded ones (undefined). format: 'glb' | 'gltf' | 'obj' | 'off' | 'ply'. */
  exportAsset(asset: number, positions: Float64Array | Float32Array | undefined, format: string,
              options: { recompute_normals?: boolean } | undefined): Result<{ bytes: Uint8Array }>;
  /** A plain mesh (no source document), optional colours #V·3 in 0..1. */
  saveMesh(format: string, positions: Float64Array | Float32Array, indices: Uint32Array,
           colors: Float32Array | Float64Array | undefined): Result<{ bytes: Uint8Array }>;
  validateMesh(positions: Float64Array | Float32Array, indices: Uint32Array,
               options: { degenerate_area_tolerance?: number } | undefined): Result<{ report: MeshReport; text: string }>;
  /** k smallest eigenpairs of Wφ = λAφ. progress returns false to cancel (code Cancelled).
   *  Refuses non-manifold input (InvalidMesh) like `meshmorph eigs`. */
  spectralBasis(positions: Float64Array | Float32Array, indices: Uint32Array,
                options: SpectralBasisOptions | undefined,
                progress: ((stage: string, fraction: number) => boolean) | undefined): Result<{
    eigenvalues: Float64Array;  // k, ascending
    vectors: Float32Array;      // k·#V, function i at [i·#V, (i+1)·#V)
    iterations: number; operations: number;
    solver: 'block Lanczos' | 'Spectra' | 'dense';
  }>;
  /** Automatic joints (wasm/bind_retarget.cpp, app/joints_job.h): the skinned source's joints
   *  fitted inside the target (glTF or mesh file). markersJson: {"joint": [x, y, z]} pins, or "".
   *  Errors: InvalidMesh (no skeleton: empty, flat or broken target), InvalidArgument (topology
   *  mismatch such as a biped skeleton on a quadruped, unknown marker or marker outside, a joint
   *  that cannot be placed inside: pin it with a marker), Cancelled. */
  retargetJoints(sourceBytes: Uint8Array, sourceName: string, targetBytes: Uint8Array, targetName: string,
                 markersJson: string, options: object | undefined,
                 progress: ((stage: string, fraction: number) => boolean) | undefined): Result<{
    json: string;                 // {"name": [x, y, z]}: retargetPrepare's targetJointsJson
    names: string[];              // #J source joint names (joints inside the source surface)
    positions: Float32Array;      // #J·3, target coordinates
    parents: number[];            // #J, -1 for roots
    skipped: string[];            // source joints outside the source surface (not placed)
    warnings: string[];
    skeletonPositions: Float32Array;  // #N·3 target curve skeleton nodes
    skeletonParents: number[];    // #N, -1 for the root
    targetUp: number;             // 0..5 = +x,+y,+z,-x,-y,-z (detected unless given)
    limbEnds: number;             // matched limb ends
  }>;
}

// ---- worker protocol (lib/protocol.js)

export type Buffers = Record<string, ArrayBufferView | ArrayBuffer>;
export type ToWorker =
  | { type: 'init'; cancelFlag?: Int32Array /* over a SharedArrayBuffer */ }
  | { type: 'run'; id: number; op: string; options: object; buffers: Buffers }
  | { type: 'cancel'; id: number };
export type FromWorker =
  | { type: 'ready'; ops: string[]; cooperativeCancel: boolean }
  | { type: 'progress'; id: number; stage: string; fraction: number }
  | { type: 'result'; id: number; buffers: Buffers; info: object }
  | { type: 'error'; id: number | null; code: string; message: string; fatal?: boolean };

/** What an op receives (ops/<module>.js). */
export interface OpContext {
  module: MeshMorphModule;
  state: { meshes: Map<string, { asset: number; name: string; format: string;
    weldedPositions: Float64Array; weldedIndices: Uint32Array; // fetched from the asset on first read
    weldedVertices: number; toWelded: Uint32Array }> } & Record<string, unknown>;
  /** Forward to core progress callbacks; false means the user cancelled. */
  progress(stage: string, fraction: number): boolean;
}
export type Op = (ctx: OpContext, options: object, buffers: Buffers) => { buffers?: Buffers; info?: object };

// ---- mesh ops (ops/mesh.js): options → result buffers / info
// load     {name, slot?, weld?, skip_unsupported_primitives?} + buffers {[name]: bytes, [sibling]: bytes}
//          → {positions, indices, normals, toWelded} / {slot, name, format, warnings, primitives,
//            report, text, infoReport, rawVertices, weldedVertices}
// validate {slot?} or buffers {positions, indices} → {} / {slot, report, text}
// eigs     {slot?, k?, ncv?, relative_shift?, tolerance?, max_iterations?, solver?}
//          → {eigenvalues, vectors} / {slot, k, weldedVertices, iterations, operations, solver, milliseconds}
// export   {slot?, format? = 'glb', recompute_normals?} + buffers {positions?}
//          → {bytes} / {fileName, format, byteLength}
// unload   {slot?} → {} / {slot, unloaded}

// ---- transfer ops (ops/transfer.js), besides transfer and compare
// suggestLandmarks {referenceSlot?, sourceSlot?, count? = 8, sameConnectivity?}
//          → {} / {pairs: [[r, s, cost]] (welded), reference, source: {centre, radius,
//            extremities: [{vertex, relative, direction}], between}}
// partTransfer {referenceSlot?, sourceSlot?, landmarks?, parts: 'auto' | part-file text,
//          partOptions?: optionSchema {job: 'transfer-parts'}, ...transfer options}
//          → {positions, positionsLevel1, partLabels: Int32Array (deepest part per welded source
//            vertex, -1 outside)} / {level1 (as transfer's info), partsJson, proposals: {tried,
//            kept, rounds, landmarkErrorLevel1, landmarkError} (automatic parts: proposal sets
//            tried over how many rounds, and the first round's set kept), parts: [{name, level,
//            round, ok, message, rejected, rigid, transferFlips, cageReused,
//            fixedCageVertices, ...}], folds, ms}
//            (hierarchical part transfer, paper 000 Sec. 4.3)
// ---- edit ops (ops/edit.js): positions results carry {positions, rawPositions, rawNormals}
// ---- debug ops (ops/debug.js; the e2e recovery checks only)
// debugExhaustMemory {} → {} / {allocatedMB};  debugCrash {} → the worker dies after answering
// ---- retarget ops (ops/retarget.js; wasm/bind_retarget.cpp)
// retargetJoints {sourceName, targetName, markersJson?, ...joints job options} + buffers {source, target}
//          → {positions, skeletonPositions} / {json, names, parents, skeletonParents, skipped,
//            warnings, targetUp, limbEnds}; retargetPrepare accepts targetJointsJson 'auto'
// ---- merge ops (ops/merge.js; bindings wasm/bind_merge.cpp: mergeMeshes, cutMesh, boundaryLoops,
//      exportAssetWithMesh in wasm/bind_mesh.cpp)
// mergeOpen  {slot, name, cuts?: [{plane: [px,py,pz,nx,ny,nz], keep?} | {disk: [vertex, radius]}]}
//            + buffers as for load → {positions, indices, normals?, toWelded, welded, weldedIndices}
//            / {slot, name, format, rawVertices, weldedVertices, faces, loops: number[][], cuts, load}
// merge      {targetSlot, sourceSlot, spec (the CLI's merge spec, object or JSON), placement?: 16}
//            → {positions: Float64Array, indices, sourcePositions} / {vertices, faces,
//              boundaryLoops, sourceOffset, stats, seams, milliseconds}
// mergeExport {slot, format? = 'glb', placement?} + buffers {positions, indices}? (none: the
//            slot's current mesh) → {bytes} / {fileName, format, byteLength}
// ---- retarget ops (ops/retarget.js; bindings wasm/bind_retarget.cpp; the page's caller is
//      lib/retarget-runner.js)
// retargetPrepare {sourceName, targetName, targetJointsJson? ('' = the target's skin),
//            jointMapJson?, ...options of optionSchema {job: 'retarget'}} + buffers {source,
//            target: bytes} → {times: Float64Array, targetPositions: Float32Array (#V·3 rest),
//            targetIndices} / {session, frames, clip, warnings: string[]}
// retargetFrames {session, first = 0, count = rest} → {positions: Float32Array (count·#V·3,
//            frame-major)} / {first, count}; progress stage 'frames', cancellable
// retargetExportGlb {session} + buffers {positions (all frames so far, frame-major)}
//            → {bytes} (the target with one morph target per frame) / {}
// retargetDispose {session} → {} / {disposed}
