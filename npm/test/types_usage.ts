// A user's code against the package's declarations (index.d.ts, render.d.ts), imported by the
// package's name as a user would. Type-checked only (tsc, test/tsconfig.json), never run: every
// `@ts-expect-error` line is a misuse the declarations must refuse.
import { load, McplayError, Status, type StudyResult } from 'mcplay';
import { load as loadRender, type RenderScene } from 'mcplay/render';

export async function study(): Promise<number | null> {
  const core = await load();
  const result: StudyResult = core.runStudy({ f: 'exp(x)', exact: Math.E - 1 }, { n_max: 4096 },
    (level) => level.n >= 1024);
  const table: string = core.format(result, 'table');
  const names: string[] = core.catalog().estimators.map((e) => e.name);
  // @ts-expect-error: no such format
  core.format(result, 'xml');
  // @ts-expect-error: options are an object or JSON text
  core.runStudy({ f: 'x' }, 42);
  try {
    core.sceneInfo({ f: 'x +* 2' });
  } catch (e) {
    if (e instanceof McplayError && e.status === Status.SCENE) return table.length + names.length;
  }
  const first = result.estimators[0].levels?.at(-1);
  return first ? first.mean : null;
}

export async function image(scene: RenderScene): Promise<string> {
  const render = await loadRender({ wasmBinary: new Uint8Array(0) });
  const shot = render.renderImage(scene, { spp: 1, outputs: ['png'] });
  // @ts-expect-error: not an output the core writes
  render.renderImage(scene, { outputs: ['jpeg'] });
  // @ts-expect-error: a render scene's glTF is the object, inline
  render.sceneInfo({ render: { gltf: 'scene.gltf' } } satisfies RenderScene);
  return shot.images.png;
}
